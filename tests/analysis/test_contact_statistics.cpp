#include "analysis/contact_statistics.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::analysis;

namespace {

Bed fcc_block(int n, double d, double squeeze = 0.0) {
  // Face-centred cubic lattice, nearest-neighbour distance d - squeeze, far from any wall.
  Bed b;
  b.container = std::make_shared<Cylinder>(1000.0);
  const double a = std::sqrt(2.0) * (d - squeeze);
  const Eigen::Vector3d basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& e : basis) {
          b.centres.push_back(a * (Eigen::Vector3d(i, j, k) + e) + Eigen::Vector3d(0, 0, 10 * d));
          b.diameters.push_back(d);
        }
  return b;
}

}  // namespace

TEST(ContactStatistics, ExactlyTouchingFccSpheresHaveTwelveContacts) {
  const Bed b = fcc_block(4, 1.0);
  const auto st = contact_statistics(b, 1e-9);
  int interior = 0;
  for (size_t i = 0; i < b.size(); ++i)
    if (st.sphere_contacts[i] == 12) ++interior;
  EXPECT_GE(interior, 8);  // at least the 2x2x2 inner cells' spheres
  for (int c : st.sphere_contacts) EXPECT_LE(c, 12);
  EXPECT_NEAR(st.max_pair_overlap, 0.0, 1e-12);
}

TEST(ContactStatistics, NearlyTouchingCountsOnlyWithinTheTolerance) {
  Bed b;
  b.container = std::make_shared<Cylinder>(10.0);
  b.centres = {{0, 0, 0.5}, {1.0 + 1e-6, 0, 0.5}};
  b.diameters = {1.0, 1.0};
  EXPECT_EQ(contact_statistics(b, 1e-7).sphere_contacts[0], 0);
  EXPECT_EQ(contact_statistics(b, 1e-4).sphere_contacts[0], 1);
  EXPECT_EQ(contact_statistics(b, 1e-4).floor_contact[0], 1);
}

TEST(ContactStatistics, OverlapsAndWallContacts) {
  Bed b;
  b.container = std::make_shared<Cylinder>(2.0);
  b.centres = {{1.5001, 0, 0.4999}, {0.5002, 0, 0.4999}};
  b.diameters = {1.0, 1.0};
  const auto st = contact_statistics(b, 1e-4);
  EXPECT_NEAR(st.max_wall_overlap, 1e-4, 1e-12);
  EXPECT_NEAR(st.max_floor_penetration, 1e-4, 1e-12);
  EXPECT_NEAR(st.max_pair_overlap, 1e-4, 1e-12);
  EXPECT_EQ(st.wall_contacts[0], 1);
  EXPECT_EQ(st.wall_contacts[1], 0);
}

TEST(ContactStatistics, ResidualOfABalancedStackIsZero) {
  // A column of three spheres under a linear contact law: overlap below sphere k carries the
  // weight of the spheres above it (2 units, then 1), so overlaps 2 e and e balance exactly.
  Bed b;
  b.container = std::make_shared<Cylinder>(0.5);
  const double e = 1e-5;
  b.centres = {{0, 0, 0.5}, {0, 0, 1.5 - 2 * e}, {0, 0, 2.5 - 3 * e}};
  b.diameters = {1, 1, 1};
  const auto st = contact_statistics(b, 1e-4);
  EXPECT_NEAR(st.residual_max, 0.0, 1e-6);
  // Break the balance: the top sphere floats.
  b.centres[2].z() += 0.1;
  EXPECT_GT(contact_statistics(b, 1e-4).residual_max, 0.5);
}

TEST(ContactStatistics, SlabCoordinationCountsOnlyCentresInsideAndSetsRattlersApart) {
  // A single-file column of 5 touching spheres in a wide tube: the floor sphere has 2 contacts
  // (floor, one above), the inner three 2 each, the top one 1; all are rattlers (< 4). The
  // slab 1.2 <= z <= 3.8 holds the spheres at z = 1.5, 2.5 and 3.5 only.
  Bed b;
  b.container = std::make_shared<Cylinder>(5.0);
  for (int k = 0; k < 5; ++k) b.centres.emplace_back(0, 0, 0.5 + k), b.diameters.push_back(1.0);
  const auto st = contact_statistics(b, 1e-6);
  const SlabCoordination in = slab_coordination(b, st, 1.2, 3.8);
  EXPECT_EQ(in.spheres, 3);
  EXPECT_DOUBLE_EQ(in.mean_sphere_contacts, 2.0);
  EXPECT_EQ(in.rattlers, 3);
  // In an inner lattice plane of the fcc block every sphere touches at least 8 others (even at
  // a corner of the plane: 4 in the plane below, 4 in the plane above or beside it), the inner
  // ones 12; none is a rattler.
  const Bed f = fcc_block(4, 1.0);
  const auto fs = contact_statistics(f, 1e-9);
  const double a = std::sqrt(2.0), mid = 10.0 + 1.5 * a;  // middle lattice plane of the block
  const SlabCoordination core = slab_coordination(f, fs, mid - 0.1, mid + 0.1);
  EXPECT_GT(core.spheres, 0);
  EXPECT_EQ(core.rattlers, 0);
  EXPECT_GT(core.mean_sphere_contacts, 8.0);
  EXPECT_LT(core.mean_sphere_contacts, 12.0);
  EXPECT_EQ(slab_coordination(f, fs, -5.0, -1.0).spheres, 0);
}
