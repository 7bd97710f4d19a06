// The gap-based edge length: analytic gaps between spheres and to a cylinder wall.
#include "meshing/surface/gap_spacing.hpp"

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

// The cells the gaps add, integrated over each sphere on a lattice, against the same integral
// over the polar angle of spheres whose medial surfaces are known: a pair 0.01 apart (the plane
// between them) and a sphere 0.01 from a flat wall (the paraboloid as far from both).
TEST(GapSpacing, AddedCellsMatchTheAxisymmetricIntegral) {
  const double r = 0.5, gap = 0.01, cells = 4.0, finest = 0.005, coarsest = 0.05, v = 0.24;
  const std::vector<Eigen::Vector3d> centres{{-r - gap / 2, 0.0, 0.0}, {r + gap / 2, 0.0, 0.0}, {-5.0 + r + gap, 3.0, 0.0}};
  const std::vector<double> radii(3, r);
  const std::vector<char> kept(3, 1);
  const Box box(10.0, 10.0, false, false);
  const GapSpacing g(centres, radii, kept, box, cells, finest, coarsest);

  // One sphere's added cells when, at polar angle t, the gap is gap_at(t) and the column along
  // the normal column_at(t) long.
  const double reach = cells * coarsest;
  auto axisymmetric = [&](auto gap_at, auto column_at) {
    const double pi = std::acos(-1.0);
    const int n = 200000;
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
      const double t = pi * (k + 0.5) / n, w = std::min(reach, gap_at(t));
      const double edge = std::clamp(w / cells, finest, coarsest), c = std::min(0.5 * reach, column_at(t));
      const double volume = r / 3.0 * (std::pow(1.0 + c / r, 3) - 1.0);
      if (edge < coarsest)
        sum += 2.0 * pi * r * r * std::sin(t) * pi / n * volume *
               (1.0 / (v * edge * edge * edge) - 1.0 / (v * coarsest * coarsest * coarsest));
    }
    return sum;
  };
  // The pair: t from the axis towards the other sphere; the medial plane is x = 0.
  const double pair = axisymmetric(
      [&](double t) { return (centres[0] + r * Eigen::Vector3d(std::cos(t), std::sin(t), 0.0) - centres[1]).norm() - r; },
      [&](double t) { return std::cos(t) > 0.0 ? (r + gap / 2) / std::cos(t) - r : 1e9; });
  // The wall: t from the axis towards it; a point D from the wall meets the medial paraboloid
  // after D / (1 + cos t).
  const double wall = axisymmetric([&](double t) { return gap + r * (1.0 - std::cos(t)); },
                                   [&](double t) { return (gap + r * (1.0 - std::cos(t))) / (1.0 + std::cos(t)); });
  const double lattice = g.added_cells_profile(v, -10.0, 10.0, 1)[0];
  EXPECT_GT(pair, 1e3);
  // Bound: 1 %; the lattice's error here was 0.023 % when this test was written.
  EXPECT_NEAR(lattice / (2.0 * pair + wall), 1.0, 0.01) << lattice << " " << 2.0 * pair + wall;
  // Only what lies between the heights counts: above the spheres' centres, half (0.497 when
  // this test was written: the lattice is not symmetric about the equator).
  EXPECT_NEAR(g.added_cells_profile(v, 0.0, 10.0, 1)[0] / lattice, 0.5, 0.02);
}
