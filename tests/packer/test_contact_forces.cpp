#include "packer/contact_forces.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::packer;

namespace {

Contacts evaluate(const Spheres& s, const Container& c) {
  NeighbourList nl(0.1);
  nl.build(s.x, s.r, c);
  Contacts out;
  evaluate_contacts(s, nl, c, out);
  return out;
}

}  // namespace

TEST(ContactForces, TwoOverlappingSpheresPushApartAlongTheirLine) {
  Cylinder c(10.0);
  Spheres s{{{0, 0, 5}, {0.9, 0, 5}}, {0.5, 0.5}, {1, 1}};
  const Contacts k = evaluate(s, c);
  EXPECT_NEAR(k.push[0].x(), -0.1, 1e-15);
  EXPECT_NEAR(k.push[1].x(), 0.1, 1e-15);
  EXPECT_NEAR(k.push[0].y(), 0.0, 1e-15);
  EXPECT_NEAR(k.max_pair_overlap, 0.1, 1e-15);
  EXPECT_NEAR(k.elastic_energy, 0.5 * 0.01, 1e-15);
  EXPECT_EQ(k.max_wall_overlap, 0.0);
}

TEST(ContactForces, ExactlyTouchingSpheresExertNoForce) {
  Cylinder c(10.0);
  Spheres s{{{0, 0, 5}, {1.0, 0, 5}}, {0.5, 0.5}, {1, 1}};
  const Contacts k = evaluate(s, c);
  EXPECT_EQ(k.push[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(k.max_pair_overlap, 0.0);
}

TEST(ContactForces, CoincidentCentresGiveFiniteOpposedPushes) {
  Cylinder c(10.0);
  Spheres s{{{1, 1, 5}, {1, 1, 5}}, {0.5, 0.5}, {1, 1}};
  const Contacts k = evaluate(s, c);
  ASSERT_TRUE(k.push[0].allFinite());
  EXPECT_NEAR((k.push[0] + k.push[1]).norm(), 0.0, 1e-15);
  EXPECT_NEAR(k.push[0].norm(), 1.0, 1e-15);
}

TEST(ContactForces, WallPushesTowardsTheAxis) {
  Cylinder c(2.0);
  Spheres s{{{0, 1.6, 5}}, {0.5}, {1}};
  const Contacts k = evaluate(s, c);
  EXPECT_NEAR(k.push[0].y(), -0.1, 1e-15);
  EXPECT_NEAR(k.max_wall_overlap, 0.1, 1e-15);
}

TEST(ContactForces, ResidualIsZeroOnTheFloorAndOneInFreeFall) {
  Cylinder c(2.0);
  Spheres s{{{0, 0, 0.5}, {1.0, 0, 3.0}}, {0.5, 0.5}, {1, 1}};
  const Contacts k = evaluate(s, c);
  const auto [rms, max] = force_residual(s, k, 100.0);
  EXPECT_NEAR(max, 1.0, 1e-15);             // the sphere in the air carries its whole weight
  EXPECT_NEAR(rms, std::sqrt(0.5), 1e-15);  // the one on the floor is balanced
}

TEST(ContactForces, StackedPairIsBalancedAtTheStaticOverlap) {
  // Upper sphere rests on the lower one: kappa * overlap = weight.
  Cylinder c(0.5);
  const double kappa = 1000.0, overlap = 1.0 / kappa;
  Spheres s{{{0, 0, 0.5}, {0, 0, 1.5 - overlap}}, {0.5, 0.5}, {1, 1}};
  const Contacts k = evaluate(s, c);
  EXPECT_NEAR(force_residual(s, k, kappa).second, 0.0, 1e-9);
}
