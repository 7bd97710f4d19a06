// Statistical mechanics of the Metropolis hard-sphere chain: known distributions, no overlap ever.
#include "packer/hard_sphere_chain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace bedforge;
using packer::HardSphereChain;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Largest overlap of any pair, wall, floor or lid, by brute force.
double worst_overlap(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& c,
                     double lid = kInf) {
  double worst = -kInf;
  const Periodicity per = c.periodicity();
  for (size_t i = 0; i < x.size(); ++i) {
    for (size_t j = i + 1; j < x.size(); ++j) worst = std::max(worst, r[i] + r[j] - per.separation(x[i], x[j]).norm());
    WallContact w[Container::kMaxWallContacts];
    const int n = c.wall_contacts(x[i], r[i], w);
    for (int k = 0; k < n; ++k) worst = std::max(worst, w[k].overlap);
    worst = std::max({worst, r[i] - x[i].z(), x[i].z() + r[i] - lid});
  }
  return worst;
}

}  // namespace

TEST(HardSphereChain, BarometricHeightsUnderGravity) {
  // Four unit spheres far apart on a wide floor at T = kT/(m* g d) = 0.5: each height above
  // contact, h = z - r, follows p(h) ~ exp(-h / T): mean T, second moment 2 T^2.
  const double T = 0.5;
  Box box(20.0, 20.0, false, false);
  HardSphereChain chain(box, 1.0, 40.0, kInf, 11);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(chain.add({-6.0 + 4.0 * i, 0.0, 0.5}, 0.5, 1.0));
  for (int c = 0; c < 2000; ++c) chain.adapt_displacement(chain.cycle(T, true), 0.3, 1e-3, 2.0);
  double m1 = 0.0, m2 = 0.0;
  int n = 0;
  for (int c = 0; c < 60000; ++c) {
    chain.cycle(T, true);
    if (c % 5) continue;
    for (const auto& p : chain.positions()) {
      const double h = p.z() - 0.5;
      m1 += h, m2 += h * h, ++n;
    }
  }
  m1 /= n, m2 /= n;
  // 48000 correlated samples: the standard error of the mean is below 0.005; 4 sigma.
  EXPECT_NEAR(m1, T, 0.02);
  EXPECT_NEAR(m2, 2 * T * T, 0.06);
}

TEST(HardSphereChain, UniformWithoutGravity) {
  // One sphere (r = 0.5) in a 4 x 4 box under a lid at 6: its centre is uniform over
  // [-1.5, 1.5]^2 x [0.5, 5.5]: means 0 and 3, variances 0.75 and 25/12.
  Box box(4.0, 4.0, false, false);
  HardSphereChain chain(box, 1.0, 6.0, 6.0, 5);
  ASSERT_TRUE(chain.add({0.0, 0.0, 3.0}, 0.5, 1.0));
  chain.set_displacement(1.0);
  double mx = 0, mz = 0, vx = 0, vz = 0;
  const int n = 100000;
  for (int c = 0; c < n; ++c) {
    chain.cycle(1.0, false);
    const auto& p = chain.positions()[0];
    mx += p.x() / n, mz += p.z() / n, vx += p.x() * p.x() / n, vz += p.z() * p.z() / n;
  }
  vz -= mz * mz;
  EXPECT_NEAR(mx, 0.0, 0.03);
  EXPECT_NEAR(mz, 3.0, 0.05);
  EXPECT_NEAR(vx, 0.75, 0.04);
  EXPECT_NEAR(vz, 25.0 / 12.0, 0.1);
}

TEST(HardSphereChain, NeverOverlapsInAnyContainer) {
  // A dense mixture (size ratio 2) settling at low temperature in an annulus and in a box
  // periodic on both sides, checked by brute force after every cycle.
  const Annulus annulus(4.0, 1.5);
  const Box periodic(5.0, 3.2, true, true);
  for (const Container* c : {static_cast<const Container*>(&annulus), static_cast<const Container*>(&periodic)}) {
    HardSphereChain chain(*c, 1.0, 30.0, 25.0, 3);
    Rng rng(8);
    std::vector<double> r;
    for (int i = 0; i < 120; ++i) {
      const double ri = i % 3 == 0 ? 0.5 : 0.25;
      for (int t = 0; t < 1000; ++t) {
        const auto xy = c->sample_centre(rng, ri);
        if (chain.add({xy.x(), xy.y(), ri + (25.0 - 2 * ri) * rng.uniform()}, ri, 8 * ri * ri * ri)) {
          r.push_back(ri);
          break;
        }
      }
    }
    ASSERT_EQ(chain.size(), r.size());
    ASSERT_GT(r.size(), 100u) << c->kind();
    chain.set_displacement(0.3);
    chain.set_lid(kInf);
    for (int k = 0; k < 300; ++k) {
      chain.cycle(0.01, true);
      ASSERT_LE(worst_overlap(chain.positions(), r, *c), 0.0) << c->kind() << " cycle " << k;
    }
  }
}

TEST(HardSphereChain, RejectsPlacementsThatOverlapOrLeave) {
  Cylinder cyl(2.0);
  HardSphereChain chain(cyl, 1.0, 10.0, 10.0, 1);
  EXPECT_TRUE(chain.add({0, 0, 0.5}, 0.5, 1));
  EXPECT_TRUE(chain.add({1.0, 0, 0.5}, 0.5, 1));    // exactly touching is allowed
  EXPECT_FALSE(chain.add({0.5, 0.8, 0.5}, 0.5, 1)); // overlaps both
  EXPECT_FALSE(chain.add({1.6, 0, 3.0}, 0.5, 1));   // through the wall
  EXPECT_FALSE(chain.add({-1.0, 0, 0.4}, 0.5, 1));  // through the floor
  EXPECT_FALSE(chain.add({-1.0, 0, 9.6}, 0.5, 1));  // through the lid
  EXPECT_EQ(chain.size(), 2u);
}

TEST(HardSphereChain, SameSeedSameChain) {
  auto run = [](std::uint64_t seed) {
    Cylinder cyl(3.0);
    HardSphereChain chain(cyl, 1.0, 12.0, 10.0, seed);
    for (int i = 0; i < 20; ++i) chain.add({-2.0 + 0.2 * i, 0.0, 0.5 + 0.45 * i}, 0.5, 1.0);
    for (int c = 0; c < 200; ++c) chain.cycle(0.05, true);
    return chain.positions();
  };
  EXPECT_EQ(run(4), run(4));
  EXPECT_NE(run(4), run(5));
}

TEST(HardSphereChain, AShakeLiftsAndStretchesTheBedWithoutOverlap) {
  // A column of touching spheres and a tilted touching pair: lift by h = 1.5 with dilation 2,
  // so the top centre (z = 4.5) rises by h + 2 h and every centre by h (1 + 2 z / 4.5).
  Cylinder cyl(1.5);
  HardSphereChain chain(cyl, 1.0, 20.0, kInf, 1);
  const std::vector<Eigen::Vector3d> before = {{0, 0, 0.5}, {0, 0, 1.5}, {0, 0, 2.5}, {1, 0, 2.5}, {0.5, 0.5, 3.25}, {0, 0, 4.5}};
  for (const auto& p : before) ASSERT_TRUE(chain.add(p, 0.5, 1.0)) << p.transpose();
  const std::vector<double> r(before.size(), 0.5);
  chain.lift(1.5, 2.0);
  const std::vector<Eigen::Vector3d> after = chain.positions();
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_NEAR(after[i].z(), before[i].z() + 1.5 * (1.0 + 2.0 * before[i].z() / 4.5), 1e-12) << i;
    EXPECT_EQ(after[i].head<2>(), before[i].head<2>()) << i;
  }
  // Vertical gaps open, horizontal ones stay (the pair side by side at z = 2.5 still touches,
  // as does the sphere at the wall): nothing overlaps.
  EXPECT_NEAR(worst_overlap(after, r, cyl), 0.0, 1e-12);
  // A rigid lift moves everything by h alone.
  chain.lift(1.0, 0.0);
  EXPECT_NEAR(chain.positions()[0].z(), after[0].z() + 1.0, 1e-12);
}

namespace {

// Largest overlap of any pair across a period `lz` and of the wall (no floor on a periodic axis).
double worst_periodic_overlap(const std::vector<Eigen::Vector3d>& x, double r, const Container& c, double lz) {
  Periodicity per;
  per.lz = lz;
  double worst = -kInf;
  for (size_t i = 0; i < x.size(); ++i) {
    for (size_t j = i + 1; j < x.size(); ++j) worst = std::max(worst, 2 * r - per.separation(x[i], x[j]).norm());
    WallContact w[Container::kMaxWallContacts];
    const int n = c.wall_contacts(x[i], r, w);
    for (int k = 0; k < n; ++k) worst = std::max(worst, w[k].overlap);
  }
  return worst;
}

}  // namespace

TEST(HardSphereChain, CompressesAPeriodicAxisToTheFirstContactExactly) {
  // Period 6: A and B (lateral 0.6, 1.4 apart in z) touch when heights scale by 0.8 / 1.4 =
  // 0.571; A and C (lateral 0.8, 0.8 apart only across the period) by 0.6 / 0.8 = 0.75; B and
  // C never (1.4 apart sideways). So the first contact is across the period, at 0.75.
  Cylinder cyl(2.0);
  cyl.set_axial_period(6.0);
  HardSphereChain chain(cyl, 1.0, 0.0, 0.0, 1);
  ASSERT_TRUE(chain.add({0.0, 0.0, 0.5}, 0.5, 1.0));
  ASSERT_TRUE(chain.add({0.6, 0.0, 1.9}, 0.5, 1.0));
  ASSERT_TRUE(chain.add({-0.8, 0.0, 5.7}, 0.5, 1.0));
  EXPECT_FALSE(chain.add({0.0, 0.0, 6.3}, 0.5, 1.0));  // at 0.3 a period down: A is there
  EXPECT_NEAR(chain.feasible_compression(), 0.75, 1e-12);
  chain.compress_to(6.0 * 0.75);
  EXPECT_EQ(chain.period(), 4.5);
  const auto& x = chain.positions();
  EXPECT_NEAR(x[0].z(), 0.375, 1e-12);
  EXPECT_NEAR(worst_periodic_overlap(x, 0.5, cyl, 4.5), 0.0, 1e-12);  // touching, not overlapping
  EXPECT_NEAR(chain.feasible_compression(), 1.0, 1e-12);
}

TEST(HardSphereChain, CompressedPeriodicSectionsNeverOverlap) {
  // 40 spheres in a periodic tube (R = 2, period 20 down to 6.5: solid fraction 0.1 to 0.26),
  // compressed halfway to the first contact between blocks of cycles, as the packer does.
  Cylinder cyl(2.0);
  cyl.set_axial_period(20.0);
  HardSphereChain chain(cyl, 1.0, 0.0, 0.0, 3);
  Rng rng(5);
  while (chain.size() < 40) {
    const Eigen::Vector2d xy = cyl.sample_centre(rng, 0.5);
    chain.add({xy.x(), xy.y(), 20.0 * rng.uniform()}, 0.5, 1.0);
  }
  for (int k = 0; k < 200 && chain.period() > 6.5; ++k) {
    for (int c = 0; c < 5; ++c) chain.adapt_displacement(chain.cycle(1.0, false), 0.3, 1e-4, 0.5);
    chain.compress_to(std::max(6.5, chain.period() * 0.5 * (1.0 + std::max(0.5, chain.feasible_compression()))));
    ASSERT_LE(worst_periodic_overlap(chain.positions(), 0.5, cyl, chain.period()), 1e-12) << "step " << k;
    for (const auto& p : chain.positions()) {
      ASSERT_GE(p.z(), 0.0);
      ASSERT_LT(p.z(), chain.period());
    }
  }
  EXPECT_EQ(chain.period(), 6.5);
}
