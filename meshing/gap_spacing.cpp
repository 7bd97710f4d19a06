#include "meshing/gap_spacing.hpp"

#include <algorithm>
#include <cmath>

namespace bedforge::meshing {

namespace {

double largest(const std::vector<double>& radii) {
  return radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end());
}

}  // namespace

// Gaps wider than cells_per_gap * coarsest ask for the coarsest edge: spheres farther than that
// do not matter, so a cell of the largest radius plus that reach holds every sphere that does
// within the 27 cells around a point.
GapSpacing::GapSpacing(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                       const std::vector<char>& kept, const Container& container, double cells_per_gap,
                       double finest, double coarsest)
    : centres_(centres), radii_(radii), container_(container), cells_(cells_per_gap), finest_(finest),
      coarsest_(coarsest), grid_(largest(radii) + cells_per_gap * coarsest) {
  for (std::size_t i = 0; i < centres.size(); ++i)
    if (kept[i]) grid_.add(centres[i], static_cast<int>(i));
}

double GapSpacing::at(const Eigen::Vector3d& p, int self) const {
  const double reach = cells_ * coarsest_;
  double gap = reach;
  grid_.near(p, [&](int j) {
    if (j != self) gap = std::min(gap, std::max(0.0, (p - centres_[j]).norm() - radii_[j]));
  });
  if (self >= 0) {
    // A wall within reach overlaps the sphere of radius `reach` about p by reach - distance.
    WallContact walls[Container::kMaxWallContacts];
    const int n = container_.wall_contacts(p, reach, walls);
    for (int k = 0; k < n; ++k) gap = std::min(gap, std::max(0.0, reach - walls[k].overlap));
  }
  return std::clamp(gap / cells_, finest_, coarsest_);
}

}  // namespace bedforge::meshing
