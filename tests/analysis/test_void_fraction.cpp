#include "analysis/void_fraction.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace bedforge;
using namespace bedforge::analysis;
constexpr double kPi = std::numbers::pi;

namespace {

// A simple cubic lattice of touching unit spheres filling a tall square-section region of a
// wide cylinder: known solid volume per height.
Bed lattice_column(int nx, int layers) {
  Bed b;
  b.container = std::make_shared<Cylinder>(10.0);
  for (int k = 0; k < layers; ++k)
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < nx; ++j) {
        b.centres.emplace_back(i - 0.5 * (nx - 1), j - 0.5 * (nx - 1), k + 0.5);
        b.diameters.push_back(1.0);
      }
  return b;
}

}  // namespace

TEST(VoidFraction, WholeAndSlabOfALattice) {
  const Bed b = lattice_column(4, 10);
  EXPECT_NEAR(bed_height(b), 10.0, 1e-15);
  const double area = kPi * 100.0, solid_per_layer = 16 * kPi / 6;
  EXPECT_NEAR(void_fraction(b, 0, 10), 1 - 10 * solid_per_layer / (area * 10), 1e-12);
  // A slab cutting through sphere centres still holds one layer's volume per unit height.
  EXPECT_NEAR(void_fraction(b, 2.5, 7.5), 1 - 5 * solid_per_layer / (area * 5), 1e-12);
}

TEST(VoidFraction, AxialProfileAveragesToTheWholeBed) {
  const Bed b = lattice_column(3, 6);
  const Profile p = axial_void_fraction(b, 0.1, bed_height(b));
  double mean = 0.0;
  for (double v : p.void_fraction) mean += v / p.void_fraction.size();
  EXPECT_NEAR(mean, void_fraction(b, 0, bed_height(b)), 1e-12);
  // Mid-plane of a layer: circles of radius 1/2 per sphere; at the touching plane: none.
  EXPECT_LT(p.void_fraction[5], p.void_fraction[0]);
}

TEST(VoidFraction, RadialProfileOfOneSphereOnTheAxis) {
  Bed b;
  b.container = std::make_shared<Cylinder>(1.0);
  b.centres = {{0, 0, 0.5}};
  b.diameters = {1.0};
  const Profile p = radial_void_fraction(b, 1.0, 0.0, 0.1, 0.0, 1.0);
  ASSERT_EQ(p.position.size(), 10u);
  for (size_t k = 0; k < p.position.size(); ++k) {
    const double ro = 1.0 - 0.1 * k, ri = ro - 0.1;
    // Solid in the shell: difference of the coaxial closed form, over the slab [0, 1].
    auto inside = [](double rho) {
      const double q = std::max(0.0, 0.25 - rho * rho);
      return 4.0 / 3.0 * kPi * (0.125 - std::pow(q, 1.5));
    };
    const double expected = 1 - (inside(ro) - inside(ri)) / (kPi * (ro * ro - ri * ri));
    EXPECT_NEAR(p.void_fraction[k], expected, 1e-9) << "bin " << k;
  }
  EXPECT_NEAR(p.void_fraction[0], 1.0, 1e-15);  // nothing within half a diameter of the wall
}

TEST(VoidFraction, RadialProfileVolumeWeightedMeanIsTheSlabValue) {
  const Bed b = lattice_column(5, 4);
  const Profile p = radial_void_fraction(b, 10.0, 0.0, 0.07, 0.3, 3.3);
  double solid = 0.0;
  for (size_t k = 0; k < p.position.size(); ++k) {
    const double ro = std::max(0.0, 10.0 - 0.07 * k), ri = std::max(0.0, ro - 0.07);
    solid += (1 - p.void_fraction[k]) * kPi * (ro * ro - ri * ri) * 3.0;
  }
  EXPECT_NEAR(1 - solid / (kPi * 100 * 3.0), void_fraction(b, 0.3, 3.3), 1e-10);
}

TEST(VoidFraction, CentreDistributionOfAWallLayer) {
  // Twelve spheres touching the wall of a tube of a = 5: every centre at exactly 0.5 d.
  Bed b;
  b.container = std::make_shared<Cylinder>(2.5);
  for (int i = 0; i < 12; ++i) {
    const double t = 2 * kPi * i / 12;
    b.centres.emplace_back(2.0 * std::cos(t), 2.0 * std::sin(t), 0.5 + i);
    b.diameters.push_back(1.0);
  }
  const CentreDistribution d = radial_centre_distribution(b, 2.5, 0.0, 0.05, 0, 100, kPi * 2.0 * 2.0);
  EXPECT_NEAR(d.fraction[10], 1.0, 1e-12);  // bin [0.5, 0.55)
}

TEST(VoidFraction, AnnulusProfilesFromBothWallsAddUpToTheSlabValue) {
  // Spheres scattered through an annulus (R_in = 2, R_out = 6): the shells of the two profiles
  // (outer wall to mid-gap, inner wall to mid-gap) tile the gap, so their solid adds up to the
  // slab's exactly.
  Bed b;
  b.container = std::make_shared<Annulus>(6.0, 2.0);
  for (int i = 0; i < 40; ++i) {
    const double t = 0.7 * i, rho = 2.5 + 3.0 * (0.5 + 0.5 * std::sin(1.3 * i));
    b.centres.emplace_back(rho * std::cos(t), rho * std::sin(t), 0.5 + 0.37 * i);
    b.diameters.push_back(1.0);
  }
  const double z1 = 1.0, z2 = 12.0;
  const Profile outer = radial_void_fraction(b, 6.0, 4.0, 0.1, z1, z2);
  const Profile inner = radial_void_fraction(b, 2.0, 4.0, 0.1, z1, z2);
  ASSERT_EQ(outer.position.size(), 20u);
  ASSERT_EQ(inner.position.size(), 20u);
  EXPECT_NEAR(inner.position.front(), 0.05, 1e-12);  // distances from the inner wall, outward
  double solid = 0.0;
  for (size_t k = 0; k < 20; ++k) {
    const double a = 6.0 - 0.1 * k, bo = a - 0.1, c = 2.0 + 0.1 * k, ci = c + 0.1;
    solid += (1 - outer.void_fraction[k]) * kPi * (a * a - bo * bo) * (z2 - z1);
    solid += (1 - inner.void_fraction[k]) * kPi * (ci * ci - c * c) * (z2 - z1);
  }
  EXPECT_NEAR(1 - solid / (kPi * (36.0 - 4.0) * (z2 - z1)), void_fraction(b, z1, z2), 1e-10);
}

TEST(VoidFraction, BoxWallProfileAddsUpToTheSlabValue) {
  // Spheres scattered in a 6 x 4 box with walls: the folded profile from the x walls tiles
  // the box, so its solid adds up to the slab's.
  Bed b;
  b.container = std::make_shared<Box>(6.0, 4.0, false, false);
  for (int i = 0; i < 30; ++i) {
    b.centres.emplace_back(2.4 * std::sin(1.7 * i), 1.4 * std::cos(0.9 * i), 0.5 + 0.41 * i);
    b.diameters.push_back(1.0);
  }
  const double z1 = 1.0, z2 = 10.0;
  const Profile p = wall_void_fraction(b, 0, 3.0, 4.0, 0.07, z1, z2);
  ASSERT_EQ(p.position.size(), 43u);
  double solid = 0.0;
  for (size_t k = 0; k < p.position.size(); ++k) {
    const double w = std::min(3.0, 0.07 * (k + 1)) - 0.07 * k;
    solid += (1 - p.void_fraction[k]) * 2 * w * 4.0 * (z2 - z1);
  }
  EXPECT_NEAR(1 - solid / (24.0 * (z2 - z1)), void_fraction(b, z1, z2), 1e-9);
  EXPECT_NEAR(p.void_fraction[0], 1.0, 1e-3);  // no sphere touches the x walls (|x| <= 2.4)
}
