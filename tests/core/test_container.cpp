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

TEST(Annulus, TouchesBothWallsWithNormalsIntoTheGap) {
  Annulus a(5.0, 2.0);
  WallContact w[Container::kMaxWallContacts];
  ASSERT_EQ(a.wall_contacts({4.7, 0.0, 1.0}, 0.5, w), 1);  // outer wall, concave
  EXPECT_NEAR(w[0].overlap, 0.2, 1e-15);
  EXPECT_NEAR(w[0].normal.x(), -1.0, 1e-15);
  ASSERT_EQ(a.wall_contacts({0.0, 2.3, 1.0}, 0.5, w), 1);  // inner wall, convex
  EXPECT_NEAR(w[0].overlap, 0.2, 1e-15);
  EXPECT_NEAR(w[0].normal.y(), 1.0, 1e-15);
  EXPECT_EQ(a.wall_contacts({3.5, 0.0, 0.0}, 1.5, w), 0);  // exactly filling the gap
  EXPECT_EQ(a.wall_contacts({3.5, 0.0, 0.0}, 1.6, w), 2);
  EXPECT_NEAR(a.cross_section_area(), M_PI * 21.0, 1e-12);
  EXPECT_DOUBLE_EQ(a.max_radius(), 1.5);
}

TEST(Annulus, SampledCentresAreUniformInTheReachableRing) {
  // Uniform on the ring lo < rho < hi: E[rho^2] = (lo^2 + hi^2) / 2; every sample inside.
  Annulus a(5.0, 2.0);
  Rng rng(4);
  const double r = 0.5, lo = 2.5, hi = 4.5;
  double mean_r2 = 0.0;
  const int n = 40000;
  WallContact w[Container::kMaxWallContacts];
  for (int i = 0; i < n; ++i) {
    const auto p = a.sample_centre(rng, r);
    ASSERT_EQ(a.wall_contacts({p.x(), p.y(), 0.0}, r, w), 0);
    mean_r2 += p.squaredNorm() / n;
  }
  // Standard error of the mean of rho^2 is below 0.03 here; 4 sigma.
  EXPECT_NEAR(mean_r2, 0.5 * (lo * lo + hi * hi), 0.12);
}

TEST(Box, WallsOnlyOnNonPeriodicSides) {
  Box b(4.0, 3.0, false, true);
  WallContact w[Container::kMaxWallContacts];
  ASSERT_EQ(b.wall_contacts({-1.8, 1.4, 0.0}, 0.5, w), 1);  // x wall; y is periodic
  EXPECT_NEAR(w[0].overlap, 0.3, 1e-15);
  EXPECT_NEAR(w[0].normal.x(), 1.0, 1e-15);
  Box corner(4.0, 3.0, false, false);
  EXPECT_EQ(corner.wall_contacts({1.8, -1.4, 0.0}, 0.5, w), 2);
  EXPECT_DOUBLE_EQ(b.max_radius(), 0.5);  // periodic side of 3 = 3 diameters of 1
  const Periodicity p = b.periodicity();
  EXPECT_EQ(p.lx, 0.0);
  EXPECT_NEAR(p.separation({0, 1.4, 0}, {0, -1.4, 0}).y(), -0.2, 1e-12);
  EXPECT_NEAR(p.wrapped({0, 1.6, 0}).y(), -1.4, 1e-12);
  // Wall only along the two x walls (each 3 long); all four sides when walled.
  EXPECT_DOUBLE_EQ(b.wall_perimeter(), 6.0);
  EXPECT_DOUBLE_EQ(corner.wall_perimeter(), 14.0);
}

TEST(Containers, AxialPeriodWrapsAlongTheAxis) {
  Cylinder c(2.0);
  EXPECT_FALSE(c.periodicity().any());
  c.set_axial_period(5.0);
  const Periodicity p = c.periodicity();
  EXPECT_TRUE(p.any());
  EXPECT_FALSE(p.lateral());
  EXPECT_NEAR(p.separation({0, 0, 4.8}, {0, 0, 0.1}).z(), -0.3, 1e-12);  // through the period
  EXPECT_NEAR(p.wrapped({1, 0, -0.5}).z(), 4.5, 1e-12);                   // into [0, H)
  EXPECT_NEAR(p.wrapped({1, 0, 5.0}).z(), 0.0, 1e-12);
  Box b(4.0, 4.0, true, false);
  b.set_axial_period(3.0);
  EXPECT_EQ(b.periodicity().lx, 4.0);
  EXPECT_EQ(b.periodicity().lz, 3.0);
  EXPECT_EQ(b.scaled(2.0)->axial_period(), 6.0);  // a change of unit keeps the period
  EXPECT_EQ(container_from_json(b.to_json())->to_json(), b.to_json());
  EXPECT_EQ(container_from_json(b.to_json())->axial_period(), 3.0);
}

TEST(Containers, HydraulicDiameterOfCircularShapesIsTheirWidth) {
  // 4 A / P: the diameter of a cylinder, the gap's width twice over for an annulus.
  const Cylinder c(1.5);
  EXPECT_NEAR(4.0 * c.cross_section_area() / c.wall_perimeter(), 3.0, 1e-12);
  const Annulus a(5.0, 2.0);
  EXPECT_NEAR(4.0 * a.cross_section_area() / a.wall_perimeter(), 6.0, 1e-12);
}

TEST(Containers, ReadWithClearErrors) {
  auto read = [](const std::string& text) {
    const toml::table t = toml::parse(text);
    SceneSection s(t["container"].as_table(), "container");
    return read_container(s, 0.001, 0.001);
  };
  EXPECT_EQ(read("[container]\ntype = \"annulus\"\ndiameter_d = 20.3\ninner_diameter_d = 6.25")->kind(), "annulus");
  EXPECT_EQ(read("[container]\ntype = \"box\"\nsize_x_d = 8\nsize_y_m = 0.008\nperiodic_x = true")->kind(), "box");
  auto message = [&](const std::string& text) {
    try {
      read(text);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("[container]\ntype = \"annulus\"\ndiameter_d = 6\ninner_diameter_d = 6").find("inner_diameter_d"),
            std::string::npos);
  // A gap narrower than a sphere.
  EXPECT_NE(message("[container]\ntype = \"annulus\"\ndiameter_d = 6\ninner_diameter_d = 4.5").find("does not fit"),
            std::string::npos);
  EXPECT_NE(message("[container]\ntype = \"box\"\nsize_x_d = 8").find("size_y"), std::string::npos);
  EXPECT_NE(message("[container]\ntype = \"box\"\nsize_x_d = 2.5\nsize_y_d = 9\nperiodic_x = true").find("3 diameters"),
            std::string::npos);
  EXPECT_NE(message("[container]\ntype = \"sphere\"\ndiameter_d = 5").find("cylinder"), std::string::npos);
  EXPECT_EQ(read("[container]\ndiameter_d = 5\nperiod_z_d = 3")->axial_period(), 0.003);
  const std::string short_period = message("[container]\ndiameter_d = 5\nperiod_z_d = 2.5");
  EXPECT_NE(short_period.find("container.period_z_d"), std::string::npos) << short_period;
  EXPECT_NE(short_period.find("3 largest diameters"), std::string::npos) << short_period;
}

TEST(Containers, JsonRoundTripOfEveryKind) {
  const std::vector<std::shared_ptr<Container>> all = {std::make_shared<Annulus>(3.0, 1.0),
                                                       std::make_shared<Box>(2.0, 5.0, true, false)};
  for (const auto& c : all) EXPECT_EQ(container_from_json(c->to_json())->to_json(), c->to_json());
}
