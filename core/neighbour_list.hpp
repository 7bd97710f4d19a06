#pragma once
#include <Eigen/Core>

#include <span>
#include <vector>

#include "core/container.hpp"
#include "core/sphere_grid.hpp"

namespace bedforge {

// Verlet list built on a cell grid (core/sphere_grid.hpp): for each sphere, every sphere whose surface is closer than
// `skin`. The list is rebuilt only when the two largest displacements since the last build sum
// to more than the skin, so between rebuilds it still holds every touching pair. Work and memory are O(N).
// Each sphere lists all its neighbours (both directions), so forces are gathered per sphere in
// parallel without atomics and in a fixed order: the result does not depend on thread count.
class NeighbourList {
 public:
  explicit NeighbourList(double skin) : skin_(skin) {}

  // x: centres, r: radii (N each, same length unit as `skin`). Returns true when it rebuilt.
  bool update(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& container);
  void build(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& container);

  std::span<const int> of(std::size_t i) const {
    return {list_.data() + offsets_[i], static_cast<std::size_t>(offsets_[i + 1] - offsets_[i])};
  }
  long builds() const { return builds_; }

 private:
  double skin_;
  long builds_ = 0;
  std::vector<std::size_t> offsets_;
  std::vector<int> list_;
  std::vector<Eigen::Vector3d> built_at_;
  // Kept so frequent rebuilds allocate nothing.
  SphereGrid grid_;
  std::vector<int> scratch_;    // n rows of capacity_ neighbours
  std::size_t capacity_ = 32;
};

}  // namespace bedforge
