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
  const Cylinder& c = dynamic_cast<const Cylinder&>(*b.container);
  const Profile p = radial_void_fraction(b, c, 0.1, 0.0, 1.0);
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
  const Cylinder& c = dynamic_cast<const Cylinder&>(*b.container);
  const Profile p = radial_void_fraction(b, c, 0.07, 0.3, 3.3);
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
  const CentreDistribution d = radial_centre_distribution(b, dynamic_cast<const Cylinder&>(*b.container), 0.05, 0, 100);
  EXPECT_NEAR(d.fraction[10], 1.0, 1e-12);  // bin [0.5, 0.55)
}
