#include "meshing/gap_spacing.hpp"

#include <algorithm>
#include <cmath>

#include "meshing/spaced_points.hpp"

namespace bedforge::meshing {

GapSpacing::GapSpacing(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                       const std::vector<char>& kept, const Container& container, double cells_per_gap,
                       double finest, double coarsest)
    : centres_(centres), radii_(radii), container_(container), cells_(cells_per_gap), finest_(finest),
      coarsest_(coarsest) {
  // Gaps wider than cells_per_gap * coarsest ask for the coarsest edge: spheres farther than
  // that do not matter, so one cell of r_max plus that reach holds every sphere that does
  // within the 27 cells around a point.
  const double r_max = radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end());
  cell_ = r_max + cells_ * coarsest_;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (!kept[i]) continue;
    const Eigen::Vector3d& c = centres[i];
    grid_[grid_cell_key(std::lround(std::floor(c.x() / cell_)), std::lround(std::floor(c.y() / cell_)),
              std::lround(std::floor(c.z() / cell_)))]
        .push_back(static_cast<int>(i));
  }
}

double GapSpacing::at(const Eigen::Vector3d& p, int self) const {
  const double reach = cells_ * coarsest_;
  double gap = reach;
  const long x = std::lround(std::floor(p.x() / cell_)), y = std::lround(std::floor(p.y() / cell_)),
             z = std::lround(std::floor(p.z() / cell_));
  for (long dx = -1; dx <= 1; ++dx)
    for (long dy = -1; dy <= 1; ++dy)
      for (long dz = -1; dz <= 1; ++dz) {
        const auto it = grid_.find(grid_cell_key(x + dx, y + dy, z + dz));
        if (it == grid_.end()) continue;
        for (int j : it->second)
          if (j != self) gap = std::min(gap, std::max(0.0, (p - centres_[j]).norm() - radii_[j]));
      }
  if (self >= 0) {
    // A wall within reach overlaps the sphere of radius `reach` about p by reach - distance.
    WallContact walls[Container::kMaxWallContacts];
    const int n = container_.wall_contacts(p, reach, walls);
    for (int k = 0; k < n; ++k) gap = std::min(gap, std::max(0.0, reach - walls[k].overlap));
  }
  return std::clamp(gap / cells_, finest_, coarsest_);
}

}  // namespace bedforge::meshing
