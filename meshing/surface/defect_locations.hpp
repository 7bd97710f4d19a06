#pragma once
#include <Eigen/Core>

#include <string>
#include <vector>

#include "core/bed.hpp"

namespace bedforge::meshing {

// Where a stage's defects (cells or triangles failing a quality gate) lie, for a diagnostic a
// user can act on. Input: `bed` (m), `points` (m, one per defect), `what` names the defects
// ("cells"). Output: nearest[k], the particle whose surface is nearest to points[k] (-1 for an
// empty bed); summary, the five particles nearest to the most defects, most first, as
// "particle 12 (5 cells), particle 3 (2 cells)".
struct DefectLocations {
  std::vector<int> nearest;
  std::string summary;
};
DefectLocations locate_defects(const Bed& bed, const std::vector<Eigen::Vector3d>& points, const std::string& what);

}  // namespace bedforge::meshing
