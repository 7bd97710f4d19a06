// The gap-based edge length: analytic gaps between spheres and to a cylinder wall.
#include "meshing/gap_spacing.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::meshing;

namespace {
// Two spheres of radius 0.5 whose surfaces are 0.1 apart along x, and a third 0.1 from the
// wall of a cylinder of radius 2; a fourth, left out of the surface, touches the first.
struct Scene {
  std::vector<Eigen::Vector3d> centres{{-0.55, 0.0, 1.0}, {0.55, 0.0, 1.0}, {0.0, 1.4, 1.0}, {-0.55, -1.0, 1.0}};
  std::vector<double> radii{0.5, 0.5, 0.5, 0.5};
  std::vector<char> kept{1, 1, 1, 0};
  Cylinder tube{2.0};
};
}  // namespace

TEST(GapSpacing, EdgeIsTheGapOverTheCellsBetweenItsBounds) {
  const Scene s;
  // 2 cells per gap, edges in [0.01, 0.2]: gaps wider than 0.4 ask for 0.2.
  const GapSpacing g(s.centres, s.radii, s.kept, s.tube, 2.0, 0.01, 0.2);
  // On sphere 0, facing sphere 1 across 0.1: 0.05. Its own surface does not count.
  EXPECT_NEAR(g.at({-0.05, 0.0, 1.0}, 0), 0.05, 1e-12);
  // Its far side is 1.1 from sphere 1's surface and 0.95 from the wall: the coarsest edge.
  EXPECT_NEAR(g.at({-1.05, 0.0, 1.0}, 0), 0.2, 1e-12);
  // Off the axis of the gap, 0.3 above it on sphere 0: the distance to sphere 1's surface.
  const Eigen::Vector3d q(-0.55 + std::sqrt(0.25 - 0.09), 0.0, 1.3);
  EXPECT_NEAR(g.at(q, 0), ((q - s.centres[1]).norm() - 0.5) / 2.0, 1e-12);
  // Sphere 2 is 0.1 from the wall: on both sides of that gap, 0.05.
  EXPECT_NEAR(g.at({0.0, 1.9, 1.0}, 2), 0.05, 1e-12);
  EXPECT_NEAR(g.at({0.0, 2.0, 1.0}, -1), 0.05, 1e-12);
  // A gap narrower than finest x cells asks for the finest edge.
  EXPECT_NEAR(g.at({0.04, 0.0, 1.0}, -1), 0.01, 1e-12);
  // Sphere 3 is not in the surface: the wall facing it keeps the coarsest edge.
  EXPECT_NEAR(g.at({-0.55, -1.55, 1.0}, -1), 0.2, 1e-12);
}
