#include "meshing/surface/defect_locations.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <map>

namespace bedforge::meshing {

DefectLocations locate_defects(const Bed& bed, const std::vector<Eigen::Vector3d>& points, const std::string& what) {
  DefectLocations out;
  out.nearest.assign(points.size(), -1);
  std::map<int, int> by_particle;
  for (std::size_t k = 0; k < points.size(); ++k) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < bed.size(); ++i) {
      const double gap = (points[k] - bed.centres[i]).norm() - 0.5 * bed.diameters[i];
      if (gap < best) best = gap, out.nearest[k] = static_cast<int>(i);
    }
    if (out.nearest[k] >= 0) ++by_particle[out.nearest[k]];
  }
  std::vector<std::pair<int, int>> most(by_particle.begin(), by_particle.end());
  std::stable_sort(most.begin(), most.end(), [](auto a, auto b) { return a.second > b.second; });
  for (std::size_t k = 0; k < std::min<std::size_t>(5, most.size()); ++k)
    out.summary += fmt::format("{}particle {} ({} {})", k ? ", " : "", most[k].first, most[k].second, what);
  return out;
}

}  // namespace bedforge::meshing
