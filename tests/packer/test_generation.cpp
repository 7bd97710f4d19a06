#include "packer/generation.hpp"

#include <gtest/gtest.h>

using namespace bedforge;
using namespace bedforge::packer;

TEST(Generation, InitialHeightFollowsEquation6) {
  // Salvat et al. (2005), Eq. (6): L0 = (2/3) d N / (a^2 (1 - eps0)), in diameters.
  const double a = 5.0, eps0 = 0.47;
  const int n = 500;
  Cylinder c(0.5 * a);
  Spheres s;
  s.r.assign(n, 0.5);
  s.w.assign(n, 1.0);
  Rng rng(1);
  const double L0 = generate_initial_bed(s, c, eps0, rng).initial_height;
  EXPECT_NEAR(L0, 2.0 / 3.0 * n / (a * a * (1 - eps0)), 1e-12);
  double zmin = 1e9, zmax = -1e9;
  for (const auto& x : s.x) {
    EXPECT_LE(std::hypot(x.x(), x.y()), 0.5 * a - 0.5 + 1e-12);  // rho <= R - d/2
    zmin = std::min(zmin, x.z()), zmax = std::max(zmax, x.z());
  }
  EXPECT_GE(zmin, 0.5);
  EXPECT_LE(zmax, L0 + 0.5);
  EXPECT_GT(zmax - zmin, 0.9 * L0);  // the draws fill the height
  for (size_t i = 1; i < s.x.size(); ++i) EXPECT_LE(s.x[i - 1].z(), s.x[i].z());  // numbered bottom-up
}
