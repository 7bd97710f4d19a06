#include "core/container.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

using namespace bedforge;

TEST(Cylinder, WallOverlapAndNormalPointToTheAxis) {
  Cylinder c(2.0);
  WallContact w[Container::kMaxWallContacts];
  ASSERT_EQ(c.wall_contacts({1.6, 0.0, 5.0}, 0.5, w), 1);
  EXPECT_NEAR(w[0].overlap, 0.1, 1e-15);
  EXPECT_NEAR(w[0].normal.x(), -1.0, 1e-15);
  EXPECT_NEAR(w[0].normal.z(), 0.0, 1e-15);
  ASSERT_EQ(c.wall_contacts({0.0, -1.7, 0.0}, 0.5, w), 1);
  EXPECT_NEAR(w[0].normal.y(), 1.0, 1e-15);
  EXPECT_EQ(c.wall_contacts({1.5, 0.0, 0.0}, 0.5, w), 0);  // exactly touching: no force
  EXPECT_EQ(c.wall_contacts({0.0, 0.0, 0.0}, 0.5, w), 0);
}

TEST(Cylinder, SampledCentresAreUniformInTheReachableDisk) {
  // Uniform on a disk of radius a: E[rho^2] = a^2 / 2.
  Cylinder c(3.0);
  Rng rng(1);
  const double r = 0.5, a = 2.5;
  double mean_r2 = 0.0;
  const int n = 40000;
  for (int i = 0; i < n; ++i) {
    const auto p = c.sample_centre(rng, r);
    const double r2 = p.squaredNorm();
    ASSERT_LE(std::sqrt(r2), a + 1e-12);
    mean_r2 += r2 / n;
  }
  // The standard deviation of rho^2 is a^2 / sqrt(12); four standard errors.
  EXPECT_NEAR(mean_r2, a * a / 2, 4 * a * a / std::sqrt(12.0 * n));
}

TEST(Cylinder, ReadsDiameterInDiametersOrMetres) {
  const auto t = parse_scene_text("[a]\ndiameter_d = 5\n[b]\ndiameter_m = 0.02\n[c]\ndiameter_d = 0.9\n", "t");
  SceneSection a(t["a"].as_table(), "a"), b(t["b"].as_table(), "b"), c(t["c"].as_table(), "c");
  const auto ca = read_container(a, 0.003, 0.003);
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*ca).radius(), 0.0075, 1e-15);
  const auto cb = read_container(b, 0.003, 0.003);
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*cb).radius(), 0.01, 1e-15);
  try {
    read_container(c, 0.003, 0.003);
    FAIL() << "a container narrower than a particle was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.diameter_d"), std::string::npos) << e.what();
  }
}

TEST(Cylinder, JsonRoundTrip) {
  Cylinder c(0.0125);
  const auto back = container_from_json(c.to_json());
  EXPECT_DOUBLE_EQ(dynamic_cast<const Cylinder&>(*back).radius(), 0.0125);
  EXPECT_THROW(container_from_json(nlohmann::json{{"type", "sphere"}}), InputError);
}
