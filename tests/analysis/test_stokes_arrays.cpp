// The simple cubic array's Stokes drag (Zick & Homsy 1982, Table 2) against an independent
// source, and the column of spheres that stands for the array: what makes it one.
#include "analysis/stokes_arrays.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace bedforge;
using bedforge::analysis::simple_cubic_array_gradient;
using bedforge::analysis::simple_cubic_column_gradient;
using bedforge::analysis::zick_homsy_simple_cubic;

namespace {

const double kPi = std::acos(-1.0), kMu = 1.0e-3, kU = 1.0e-5, kD = 0.003;

// A column of `n` spheres of diameter kD at solid fraction `phi`: a box of side L, centres on
// the axis at L / 2 + k L.
Bed column(double phi, int n, double side_y_scale = 1.0) {
  const double L = kD * std::cbrt(kPi / (6.0 * phi));
  Bed bed;
  bed.container = std::make_shared<Box>(L, side_y_scale * L, false, false);
  for (int k = 0; k < n; ++k) bed.centres.emplace_back(0.0, 0.0, (k + 0.5) * L), bed.diameters.push_back(kD);
  return bed;
}

double side(const Bed& bed) { return dynamic_cast<const Box&>(*bed.container).size_x(); }

}  // namespace

// Hasimoto (1959, J. Fluid Mech. 5, 317), the dilute limit: 1 / K = 1 - 1.7601 phi^(1/3) + phi -
// 1.5593 phi^2 + O(phi^(8/3)). At phi = 0.027 the next term (3.9799 phi^(8/3)) is 2.6e-4, within
// the table's 0.1 %, which is the bound.
TEST(ZickHomsy, TheDiluteEndAgreesWithHasimotosSeries) {
  const double phi = 0.027;
  const double hasimoto = 1.0 / (1.0 - 1.7601 * std::cbrt(phi) + phi - 1.5593 * phi * phi);
  ASSERT_TRUE(zick_homsy_simple_cubic(phi));
  EXPECT_NEAR(*zick_homsy_simple_cubic(phi) / hasimoto, 1.0, 1e-3);
}

// Between the tabulated fractions there is no value: an interpolation's error would pass for the
// reference's.
TEST(ZickHomsy, OnlyTabulatedFractionsHaveAValue) {
  EXPECT_TRUE(zick_homsy_simple_cubic(0.216 * (1.0 + 5e-5)));
  EXPECT_FALSE(zick_homsy_simple_cubic(0.216 * (1.0 + 5e-3)));
  EXPECT_FALSE(zick_homsy_simple_cubic(0.3));
}

// The gradient over whole cells carries each cell's sphere: G L^3 = F = 6 pi mu a K U.
TEST(SimpleCubicColumn, EachCellsPressureDropCarriesItsSphere) {
  const Bed bed = column(0.216, 6);
  const double L = side(bed);
  const auto g = simple_cubic_column_gradient(bed, kMu, kU, 1.2 * L, 5.2 * L);
  ASSERT_TRUE(g);
  EXPECT_NEAR(*g * L * L * L / (6.0 * kPi * kMu * 0.5 * kD * *zick_homsy_simple_cubic(0.216) * kU), 1.0, 1e-12);
}

TEST(SimpleCubicColumn, AnythingElseHasNoKnownAnswer) {
  const Bed good = column(0.216, 6);
  const double L = side(good);
  auto gradient = [&](const Bed& b, double z_low = -1.0, double z_high = -1.0) {
    return simple_cubic_column_gradient(b, kMu, kU, z_low < 0 ? 1.2 * L : z_low, z_high < 0 ? 5.2 * L : z_high);
  };
  ASSERT_TRUE(gradient(good));
  EXPECT_FALSE(gradient(good, 1.2 * L, 4.7 * L));  // the planes at different phases
  EXPECT_FALSE(gradient(column(0.216, 6, 1.1)));   // a rectangular box
  EXPECT_FALSE(gradient(column(0.2, 6)));          // an untabulated fraction
  Bed moved = good;
  moved.centres[3].x() += 1e-3 * L;
  EXPECT_FALSE(gradient(moved));
  Bed gap = good;
  gap.centres.back().z() += 0.5 * L;
  EXPECT_FALSE(gradient(gap));
  Bed mixed = good;
  mixed.diameters[2] *= 0.99;
  EXPECT_FALSE(gradient(mixed));
  Bed periodic = good;
  periodic.container = std::make_shared<Box>(L, L, true, true);
  EXPECT_FALSE(gradient(periodic));  // periodic sides are not the array's mirror planes
  Bed section = good;                // periodic along the column: the array itself, three cells of it
  auto tube = std::make_shared<Box>(L, L, false, false);
  tube->set_axial_period(3.0 * L);
  section.container = tube;
  section.centres.resize(3);
  section.diameters.resize(3);
  EXPECT_TRUE(gradient(section, 1.0 * L, 4.0 * L));
  Bed shuffled = good;  // the order of the rows does not matter
  std::swap(shuffled.centres[0], shuffled.centres[4]);
  EXPECT_TRUE(gradient(shuffled));
}

namespace {

// 27 spheres of diameter kD on a cubic lattice at solid fraction `phi`, offset by `offset`
// (in spacings), in a cube of three spacings periodic on every side.
Bed cubic_array(double phi, const Eigen::Vector3d& offset) {
  const double L = kD * std::cbrt(kPi / (6.0 * phi));
  Bed b;
  auto box = std::make_shared<Box>(3.0 * L, 3.0 * L, true, true);
  box->set_axial_period(3.0 * L);
  b.container = box;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        b.centres.push_back(L * (Eigen::Vector3d(i - 1, j - 1, k) + offset)), b.diameters.push_back(kD);
  return b;
}

}  // namespace

// The whole array in a box periodic on every side: the same drag per sphere as the column's, at
// any offset of the lattice; a sphere off it, unequal spheres or an untabulated fraction none.
TEST(SimpleCubicArray, ABoxPeriodicOnEverySideHoldsTheWholeArray) {
  const Bed good = cubic_array(0.216, {0.3, 0.1, 0.45});
  const double L = good.container->periodicity().lx / 3.0;
  const auto g = simple_cubic_array_gradient(good, kMu, kU);
  ASSERT_TRUE(g);
  EXPECT_NEAR(*g * L * L * L / (6.0 * kPi * kMu * 0.5 * kD * *zick_homsy_simple_cubic(0.216) * kU), 1.0, 1e-12);
  Bed moved = good;
  moved.centres[13].y() += 1e-3 * L;
  EXPECT_FALSE(simple_cubic_array_gradient(moved, kMu, kU));
  Bed mixed = good;
  mixed.diameters[5] *= 0.9;
  EXPECT_FALSE(simple_cubic_array_gradient(mixed, kMu, kU));
  EXPECT_FALSE(simple_cubic_array_gradient(cubic_array(0.2, {0.5, 0.5, 0.5}), kMu, kU));
  EXPECT_FALSE(simple_cubic_array_gradient(column(0.216, 6), kMu, kU));  // walls that slip: the column's own rule
}
