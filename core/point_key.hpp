#pragma once
#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace bedforge {

// A point's exact coordinates as a hash key: the points two meshes share (a plane between
// slabs or pieces) are the same doubles on both sides (the surface stage rounds every point to
// 12 digits), so they can be matched without a tolerance.
struct PointKey {
  double x, y, z;
  explicit PointKey(const Eigen::Vector3d& p) : x(p.x()), y(p.y()), z(p.z()) {}
  bool operator==(const PointKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PointKeyHash {
  std::size_t operator()(const PointKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (double c : {k.x, k.y, k.z}) {
      std::uint64_t b;
      std::memcpy(&b, &c, sizeof b);
      h = (h ^ b) * 1099511628211ull;
    }
    return h;
  }
};

// Points in the order of their coordinates (x, then y, then z): an order two meshes holding the
// same points under other numbers agree on.
inline bool coordinates_less(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

}  // namespace bedforge
