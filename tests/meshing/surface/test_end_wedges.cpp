// Spheres' ends near a cut plane: which are found, and the vertices graded about them on the
// sphere and on the plane.
#include "meshing/surface/end_wedges.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace bedforge::meshing;

namespace {

// The gap between the plane and a sphere of radius r whose end lies `gap` from it, at distance
// rho from the end's axis; where the plane cuts the sphere (gap < 0), not less than the cut's depth.
double gap_at(double gap, double r, double rho) { return std::max(std::abs(gap), gap + r - std::sqrt(r * r - rho * rho)); }

}  // namespace

TEST(EndWedges, EndsWithinTheReachOfAPlaneAreFoundOnBothSidesAndInOneOrderWhateverTheSpheresOrder) {
  // Unit spheres about the plane z = 0; coarse 0.2, so ends within 0.1 of it count.
  std::vector<Eigen::Vector3d> centres{{0.0, 0.0, 0.503},  {1.2, 0.0, -0.55},   // above by 0.003, below by 0.05
                                       {0.0, 1.2, 0.7},    {1.2, 1.2, 0.3},     // 0.2 off; cut 0.2 inside its end
                                       {-1.2, 0.0, -0.59}, {2.4, 0.0, 0.5},     // 0.09 below; touching it
                                       {-1.2, 1.2, 0.47}};                      // cut 0.03 inside its bottom
  const std::vector<double> radii(centres.size(), 0.5);
  const auto ends = ends_near_planes(centres, radii, {0.0}, 0.2);
  ASSERT_EQ(ends.size(), 4u);
  EXPECT_EQ(ends[0].sphere, 4);
  EXPECT_FALSE(ends[0].above);
  EXPECT_NEAR(ends[0].gap(), 0.09, 1e-12);
  EXPECT_EQ(ends[1].sphere, 6);
  EXPECT_TRUE(ends[1].above);
  EXPECT_NEAR(ends[1].gap(), -0.03, 1e-12);
  EXPECT_EQ(ends[2].sphere, 0);
  EXPECT_TRUE(ends[2].above);
  EXPECT_NEAR(ends[2].gap(), 0.003, 1e-12);
  EXPECT_EQ(ends[3].sphere, 1);
  EXPECT_NEAR(ends[3].gap(), 0.05, 1e-12);

  // The windows of a plane hold its spheres in other orders: the ends come out alike.
  std::vector<std::size_t> order(centres.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::mt19937 shuffle(3);
  std::shuffle(order.begin(), order.end(), shuffle);
  std::vector<Eigen::Vector3d> shuffled;
  for (std::size_t i : order) shuffled.push_back(centres[i]);
  const auto again = ends_near_planes(shuffled, radii, {0.0}, 0.2);
  ASSERT_EQ(again.size(), ends.size());
  for (std::size_t k = 0; k < ends.size(); ++k) EXPECT_EQ(again[k].centre, ends[k].centre);
}

TEST(EndWedges, SpheresWhoseSurfaceComesWithinReachOfAPlaneAreFoundOnceInOneOrderWhateverTheSpheresOrder) {
  // Spheres of radius 0.5 about the planes z = 0 and z = 3, reach 0.2: surfaces within 0.2 count.
  std::vector<Eigen::Vector3d> centres{{0.0, 0.0, 0.69},  {1.2, 0.0, -0.71},  // 0.19 above; 0.21 below
                                       {0.0, 1.2, 0.0},   {2.0, 0.0, 3.69},   // cut through; 0.19 above the other
                                       {3.0, 0.0, 1.5}};                      // between, near neither
  std::vector<double> radii(centres.size(), 0.5);
  const std::vector<SphereNearPlane> found = spheres_near_planes(centres, radii, {0.0, 3.0}, 0.2);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].centre, centres[0]);
  EXPECT_EQ(found[1].centre, centres[2]);
  EXPECT_EQ(found[2].centre, centres[3]);
  // Near both planes at once (a thin slab between them), still once.
  EXPECT_EQ(spheres_near_planes({{0.0, 0.0, 0.5}}, {0.5}, {0.0, 1.0}, 0.2).size(), 1u);
  std::reverse(centres.begin(), centres.end());
  const std::vector<SphereNearPlane> again = spheres_near_planes(centres, radii, {0.0, 3.0}, 0.2);
  ASSERT_EQ(again.size(), found.size());
  for (std::size_t i = 0; i < found.size(); ++i) EXPECT_EQ(again[i].centre, found[i].centre);
}

TEST(EndWedges, RingsAreSpacedAtTwiceTheGapUnderThemUpToTheCoarseEdge) {
  // A gap below 0: the plane cuts the sphere that deep inside its end.
  for (double gap : {1e-4, 0.0023, 0.03, -0.0023, -0.03}) {
    SCOPED_TRACE(gap);
    const EndNearPlane e{0.0, {0.0, 0.0, 0.5 + gap}, 0.5, true, 0};
    const double coarse = 0.2;
    const auto rings = end_rings(e, coarse);
    ASSERT_GE(rings.size(), 1u);
    EXPECT_EQ(rings.front().first, 0.0);
    for (std::size_t k = 0; k < rings.size(); ++k) {
      const auto [rho, spacing] = rings[k];
      EXPECT_NEAR(spacing, kWedgeEdgePerGap * gap_at(gap, 0.5, rho), 1e-12);
      EXPECT_LT(spacing, coarse);
      if (k > 0) {
        EXPECT_NEAR(rho - rings[k - 1].first, std::sqrt(3.0) / 2.0 * rings[k - 1].second, 1e-12);
      }
    }
    // The rings stop where the next would be as coarse as the edge around them, or past the
    // sphere's equator.
    const auto [rho, spacing] = rings.back();
    const double next = rho + std::sqrt(3.0) / 2.0 * spacing;
    EXPECT_TRUE(next >= 0.5 || kWedgeEdgePerGap * gap_at(gap, 0.5, next) >= coarse) << next;
  }
}

TEST(EndWedges, SeedsLieOnTheSphereFacingThePlaneAndOnThePlaneUnderIt) {
  const EndNearPlane e{2.0, {0.3, -0.2, 2.0 - 0.5 - 0.002}, 0.5, false, 0};  // below the plane
  ASSERT_NEAR(e.gap(), 0.002, 1e-12);
  const Seeds on_sphere = sphere_end_seeds(e, 0.15), on_plane = plane_end_seeds(e, 0.15);
  ASSERT_EQ(on_sphere.size(), on_plane.size());
  ASSERT_GT(on_sphere.size(), 100u);  // some 400 where the gap is 0.002 for 0.05 around
  EXPECT_EQ(on_sphere.front().first, e.end());
  for (std::size_t k = 0; k < on_sphere.size(); ++k) {
    const auto& [p, s] = on_sphere[k];
    EXPECT_NEAR((p - e.centre).norm(), 0.5, 1e-12);
    EXPECT_GT(p.z(), e.centre.z());
    const double rho = (p - e.centre).head<2>().norm();
    // Spaced for the gap under it (the jitter moves a point by 1e-3 of its spacing).
    EXPECT_LE(s, kWedgeEdgePerGap * gap_at(0.002, 0.5, rho) * (1.0 + 1e-2));
    const auto& [q, t] = on_plane[k];
    EXPECT_EQ(q.z(), 2.0);
    EXPECT_EQ(t, s);
  }
  // The plane's rings are turned against the sphere's: no ring vertex on the plane lies under
  // one on the sphere.
  for (std::size_t k = 1; k < on_plane.size(); ++k)
    for (const auto& [p, s] : on_sphere)
      EXPECT_GT((on_plane[k].first - p).head<2>().norm(), 0.2 * on_plane[k].second);
}
