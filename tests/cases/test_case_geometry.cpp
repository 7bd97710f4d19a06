// Where the case puts the point snappyHexMesh keeps its cells around (cases/case_writer).
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "cases/case_writer.hpp"
#include "core/container.hpp"

using bedforge::Bed;

namespace {

// How far p lies from the nearest sphere, wall, inlet or outlet (negative outside the fluid),
// computed here without the case code: the walls as the container's own contact test sees a
// sphere of radius r at p.
double clearance(const Bed& bed, const bedforge::cases::CaseGeometry& g, const Eigen::Vector3d& p) {
  double c = std::min(p.z() - g.inlet_z, g.outlet_z - p.z());
  for (std::size_t i = 0; i < bed.size(); ++i) c = std::min(c, (bed.centres[i] - p).norm() - 0.5 * bed.diameters[i]);
  bedforge::WallContact touch[bedforge::Container::kMaxWallContacts];
  if (bed.container->wall_contacts(p, 1e-12, touch) > 0) return -1.0;
  double lo = 0.0, hi = std::max(c, 0.0);  // the largest sphere at p free of the walls, by bisection
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (bed.container->wall_contacts(p, mid, touch) > 0 ? hi : lo) = mid;
  }
  return std::min(c, lo);
}

// Four columns of three unit spheres touching, in a tube of diameter 3, with 1 d empty below
// and above: the most open places are the middles of those two plenums, 0.5 d from everything.
Bed stacked_bed() {
  Bed bed;
  bed.container = std::make_shared<bedforge::Cylinder>(1.5);
  for (double z : {0.5, 1.5, 2.5})
    for (double x : {-0.5, 0.5})
      for (double y : {-0.5, 0.5}) bed.centres.emplace_back(x, y, z), bed.diameters.push_back(1.0);
  return bed;
}

}  // namespace

// The point snappyHexMesh keeps the cells around: in the fluid, as clear of every surface as
// the search lattice allows. Its nodes lie 0.25 d apart at most, at cell centres, so the
// nearest node to a plenum's middle is 0.125 d off it: at least 0.375 d clear.
TEST(CaseGeometry, TheFluidPointIsTheMostOpenPlaceOfTheDomain) {
  const Bed bed = stacked_bed();
  bedforge::cases::CaseGeometry g;
  g.d_ref = 1.0;
  g.lateral_bounds = bed.container->lateral_bounds();
  g.inlet_z = -1.0, g.outlet_z = 4.0;
  const Eigen::Vector3d p = bedforge::cases::fluid_point(bed, g);
  EXPECT_GE(clearance(bed, g, p), 0.375 - 1e-9) << p.transpose();
  // A window through the bed (no plenum) still gives a point in the fluid, between the spheres.
  g.inlet_z = 0.8, g.outlet_z = 2.2;
  const Eigen::Vector3d q = bedforge::cases::fluid_point(bed, g);
  EXPECT_GT(clearance(bed, g, q), 0.1) << q.transpose();
  // An annulus: not in the inner cylinder, whose middle is the box's.
  Bed ring;
  ring.container = std::make_shared<bedforge::Annulus>(2.0, 0.5);
  g.lateral_bounds = ring.container->lateral_bounds();
  g.inlet_z = 0.0, g.outlet_z = 4.0;
  const Eigen::Vector3d r = bedforge::cases::fluid_point(ring, g);
  EXPECT_GT(clearance(ring, g, r), 0.6) << r.transpose();  // the ring is 1.5 wide: 0.75 at its middle
}
