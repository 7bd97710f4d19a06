#include "analysis/segregation.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::analysis;

namespace {

// Species A (d = 1) and B (d = 0.5) placed layer by layer, each sphere inside one layer of
// height 1; `a_layer(k)` says how many A spheres layer k holds (the rest of 8 places are B).
Bed layered(int layers, int (*a_in_layer)(int)) {
  Bed b;
  b.container = std::make_shared<Box>(10.0, 10.0, false, false);
  for (int k = 0; k < layers; ++k)
    for (int m = 0; m < 8; ++m) {
      const bool a = m < a_in_layer(k);
      b.centres.emplace_back(-4.0 + m, 0.0, k + 0.5);
      b.diameters.push_back(a ? 1.0 : 0.5);
    }
  return b;
}

}  // namespace

TEST(Segregation, SeparatedSpeciesGiveIntensityOne) {
  const Bed b = layered(6, [](int k) { return k < 3 ? 8 : 0; });
  const Segregation s = axial_segregation(b, 1.0, 6.0);
  ASSERT_EQ(s.diameters.size(), 2u);
  EXPECT_DOUBLE_EQ(s.diameters[0], 1.0);
  EXPECT_NEAR(s.intensity, 1.0, 1e-12);
  EXPECT_NEAR(s.mean_height[0], 1.5, 1e-12);
  EXPECT_NEAR(s.mean_height[1], 4.5, 1e-12);
  // Volume fractions: 8 unit spheres in a 10 x 10 x 1 layer.
  EXPECT_NEAR(s.volume_fraction[0][0], 8 * std::acos(-1.0) / 6.0 / 100.0, 1e-12);
  EXPECT_NEAR(s.volume_fraction[1][0], 0.0, 1e-15);
}

TEST(Segregation, EvenlyMixedLayersGiveIntensityZero) {
  const Bed b = layered(6, [](int) { return 3; });
  EXPECT_NEAR(axial_segregation(b, 1.0, 6.0).intensity, 0.0, 1e-12);
}

TEST(Segregation, OneSizeIsNoMixture) {
  const Bed b = layered(3, [](int) { return 8; });
  EXPECT_TRUE(axial_segregation(b, 1.0, 3.0).diameters.empty());
}
