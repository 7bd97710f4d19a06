#pragma once
#include <Eigen/Core>

#include <array>
#include <cmath>
#include <unordered_map>
#include <vector>

namespace bedforge::meshing {

// Candidate mesh vertices (spheres, walls), accepted in order when no accepted vertex lies closer
// than 0.8 x the mean of their spacings (a Poisson-disk rule with local sizes): a uniform grid
// of cell `cell` >= every spacing keeps the test to the 27 neighbouring cells.
class SpacedPoints {
 public:
  explicit SpacedPoints(double cell) : cell_(cell) {}
  bool fits(const Eigen::Vector3d& p, double spacing) const {
    const auto k = key(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(pack(k[0] + dx, k[1] + dy, k[2] + dz));
          if (it == grid_.end()) continue;
          for (int q : it->second)
            if ((points[q] - p).norm() < 0.4 * (spacing + spacing_[q])) return false;
        }
    return true;
  }
  void add(const Eigen::Vector3d& p, double spacing) {
    const auto k = key(p);
    grid_[pack(k[0], k[1], k[2])].push_back(static_cast<int>(points.size()));
    points.push_back(p);
    spacing_.push_back(spacing);
  }
  double spacing(int i) const { return spacing_[i]; }
  std::vector<Eigen::Vector3d> points;

 private:
  std::array<long, 3> key(const Eigen::Vector3d& p) const {
    return {static_cast<long>(std::floor(p.x() / cell_)), static_cast<long>(std::floor(p.y() / cell_)),
            static_cast<long>(std::floor(p.z() / cell_))};
  }
  static long pack(long x, long y, long z) { return (x * 73856093L) ^ (y * 19349663L) ^ (z * 83492791L); }
  double cell_;
  std::unordered_map<long, std::vector<int>> grid_;
  std::vector<double> spacing_;
};

}  // namespace bedforge::meshing
