#include "core/intersection_volumes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/random.hpp"

using namespace bedforge;
constexpr double kPi = std::numbers::pi;

TEST(SphereSlab, WholeHalfAndCap) {
  const double r = 0.7, v = 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(sphere_slab_volume(r, 2.0, -10, 10), v, 1e-14);
  EXPECT_NEAR(sphere_slab_volume(r, 2.0, 2.0, 10), 0.5 * v, 1e-14);
  const double h = 0.2;  // cap of height h: pi h^2 (3r - h) / 3
  EXPECT_NEAR(sphere_slab_volume(r, 2.0, 2.0 + r - h, 5), kPi * h * h * (3 * r - h) / 3, 1e-14);
  EXPECT_EQ(sphere_slab_volume(r, 2.0, 3.0, 4.0), 0.0);
  EXPECT_EQ(sphere_slab_volume(r, 2.0, 2.5, 2.5), 0.0);
}

TEST(DiskLens, LimitsAndSymmetricCase) {
  EXPECT_NEAR(disk_lens_area(1.0, 0.0, 2.0), kPi, 1e-14);        // inside
  EXPECT_NEAR(disk_lens_area(3.0, 0.5, 2.0), 4 * kPi, 1e-14);    // contains
  EXPECT_EQ(disk_lens_area(1.0, 3.0, 2.0), 0.0);                 // apart
  // Two unit disks at distance 1: 2 pi / 3 - sqrt(3) / 2.
  EXPECT_NEAR(disk_lens_area(1.0, 1.0, 1.0), 2 * kPi / 3 - std::sqrt(3.0) / 2, 1e-14);
}

TEST(SphereCylinder, CoaxialClosedForm) {
  // Sphere on the axis inside a cylinder of radius rho < r: 4/3 pi (r^3 - (r^2 - rho^2)^(3/2)).
  const double r = 0.5;
  for (double rho : {0.1, 0.3, 0.49, 0.5, 0.8}) {
    const double q = std::max(0.0, r * r - rho * rho);
    const double exact = 4.0 / 3.0 * kPi * (r * r * r - std::pow(q, 1.5));
    EXPECT_NEAR(sphere_cylinder_volume(r, 0.0, 0.0, rho, -1, 1), exact, 1e-9 * exact) << rho;
  }
}

TEST(SphereCylinder, OffAxisAgainstMonteCarlo) {
  // Independent estimate by sampling points in the sphere; 1e6 points give about 1e-3 relative.
  const double r = 0.5, s = 0.9, rho = 1.0, z1 = -0.2, z2 = 0.45;
  bedforge::Rng rng(4);
  const int n = 1000000;
  int inside = 0, total = 0;
  for (int i = 0; i < n; ++i) {
    const double x = (2 * rng.uniform() - 1) * r, y = (2 * rng.uniform() - 1) * r, z = (2 * rng.uniform() - 1) * r;
    if (x * x + y * y + z * z > r * r) continue;
    ++total;
    if (z >= z1 && z <= z2 && (x + s) * (x + s) + y * y <= rho * rho) ++inside;
  }
  const double sphere = 4.0 / 3.0 * kPi * r * r * r;
  const double mc = sphere * inside / total;
  const double sigma = sphere * std::sqrt(double(inside) * (total - inside) / total) / total;
  EXPECT_NEAR(sphere_cylinder_volume(r, s, 0.0, rho, z1, z2), mc, 4 * sigma);
}

TEST(SphereCylinder, ShellsAddUpToTheSphere) {
  // Differences of the cumulative volume over radii tile the sphere: the invariant the radial
  // profile relies on, here with bins that cut the sphere in every way (edges through the
  // centre, tangent to it, inside it).
  const double r = 0.5, s = 1.23, zc = 0.7;
  double sum = 0.0, prev = 0.0;
  for (double rho = 0.05; rho < 3.0; rho += 0.05) {
    const double v = sphere_cylinder_volume(r, s, zc, rho, -5, 5);
    EXPECT_GE(v, prev - 1e-15);
    sum += v - prev;
    prev = v;
  }
  EXPECT_NEAR(sum, 4.0 / 3.0 * kPi * r * r * r, 1e-12);
  // Monotone and exact at the tangent radii.
  EXPECT_NEAR(sphere_cylinder_volume(r, s, zc, s - r, -5, 5), 0.0, 1e-15);
  EXPECT_NEAR(sphere_cylinder_volume(r, s, zc, s + r, -5, 5), 4.0 / 3.0 * kPi * r * r * r, 1e-15);
}

TEST(SphereCylinder, NearlyFlatWallCutsAwayTheSagitta) {
  // Centre on the wall of a very wide cylinder: half the sphere lies inside, less the sliver
  // between the tangent plane and the curved wall. The wall sits y^2 / (2 s) behind the plane at
  // lateral offset y, so the sliver is the integral of y^2 / (2 s) over the disk: pi r^4 / (8 s).
  // (s = 100 keeps the next term, pi r^6 / (64 s^3) ~ 8e-10, below the tolerance.)
  const double r = 0.5, s = 100.0;
  const double expected = 2.0 / 3.0 * kPi * r * r * r - kPi * std::pow(r, 4) / (8 * s);
  EXPECT_NEAR(sphere_cylinder_volume(r, s, 0, s, -1, 1), expected, 1e-8);
}

TEST(SphereHalfspace, CapClosedFormsAndSplitByHeight) {
  // Sphere r = 1 at the origin cut by the plane x = t, all heights: V = 4/3 pi - cap(1 - t),
  // cap(h) = pi h^2 (3 r - h) / 3; the parts above and below z = 0.3 add up to it.
  const double pi = std::acos(-1.0);
  for (double t : {-0.9, -0.3, 0.0, 0.45, 0.99}) {
    const double h = 1.0 - t, expected = 4.0 / 3.0 * pi - pi * h * h * (3.0 - h) / 3.0;
    EXPECT_NEAR(sphere_halfspace_volume(1.0, 0.0, 0.0, t, -2.0, 2.0), expected, 1e-7 * expected) << t;
    EXPECT_NEAR(sphere_halfspace_volume(1.0, 0.0, 0.0, t, -2.0, 0.3) +
                    sphere_halfspace_volume(1.0, 0.0, 0.0, t, 0.3, 2.0),
                expected, 1e-7 * expected);
  }
  EXPECT_NEAR(sphere_halfspace_volume(0.5, 2.0, 1.0, 1.0, 0.0, 3.0), 0.0, 1e-15);  // beyond the plane
}

// A whole sphere as a solid of revolution about any axis: between two planes it is the closed
// form's slab, whatever the axis's tilt (the planes cut its disks in segments).
TEST(RevolutionSlab, SphereAboutAnyAxisIsTheClosedFormSlab) {
  const double r = 0.7, zc = 1.3;
  const auto section = [r](double t) { return std::sqrt(std::max(0.0, r * r - t * t)); };
  for (double axis_z : {0.0, 0.3, std::sqrt(0.5), 0.95, 1.0, -0.6})
    for (auto [z1, z2] : {std::pair{1.0, 1.5}, std::pair{0.0, 1.2}, std::pair{1.9, 3.0}, std::pair{-1.0, 5.0}}) {
      // The axis through the centre, t measured from it.
      const double v = revolution_slab_volume(zc, axis_z, -r, r, section, z1, z2);
      EXPECT_NEAR(v, sphere_slab_volume(r, zc, z1, z2), 1e-9 * sphere_slab_volume(r, zc, -10, 10))
          << "axis_z " << axis_z << ", planes " << z1 << " " << z2;
    }
}

// A cap cut off by a vertical plane x = x_max, between two planes: the sphere's slab less the
// part left of that plane (sphere_halfspace_volume, integrated another way).
TEST(RevolutionSlab, HorizontalCapAgainstTheHalfSpace) {
  const double r = 0.5, xc = 0.2, zc = 0.0;
  for (double h : {0.1, 0.3, 0.45})
    for (auto [z1, z2] : {std::pair{-0.2, 0.1}, std::pair{0.05, 0.4}, std::pair{-1.0, 1.0}}) {
      const double cap = revolution_slab_volume(zc, 0.0, h, r, [r](double t) { return std::sqrt(std::max(0.0, r * r - t * t)); },
                                                z1, z2);
      const double expected = sphere_slab_volume(r, zc, z1, z2) - sphere_halfspace_volume(r, xc, zc, xc + h, z1, z2);
      EXPECT_NEAR(cap, expected, 1e-7 * (kPi * r * r * r)) << "h " << h << ", planes " << z1 << " " << z2;
    }
}

// Cylinders: lying down, each unit of length holds the disk's segment between the planes; standing,
// the length between the planes times the disk.
TEST(RevolutionSlab, CylindersLyingAndStanding) {
  const double rho = 0.1, L = 0.4;
  const auto constant = [rho](double) { return rho; };
  // Lying (axis horizontal, centre line at z = 0), the planes at -0.05 and 1: the disk above
  // z = -0.05, a segment of half-angle acos(0.5) cut off below.
  const double below = rho * rho * std::acos(0.5) - 0.05 * std::sqrt(rho * rho - 0.05 * 0.05);
  EXPECT_NEAR(revolution_slab_volume(0.0, 0.0, 0.0, L, constant, -0.05, 1.0), L * (kPi * rho * rho - below),
              1e-12);
  // Standing from z = 0.2 to 0.6, the planes at 0.3 and 2: 0.3 of its length.
  EXPECT_NEAR(revolution_slab_volume(0.2, 1.0, 0.0, L, constant, 0.3, 2.0), 0.3 * kPi * rho * rho, 1e-9);
  // Tilted, wholly between the planes: the whole cylinder.
  EXPECT_NEAR(revolution_slab_volume(0.0, 0.6, 0.0, L, constant, -0.5, 0.5), L * kPi * rho * rho, 1e-12);
  // Nothing between planes it does not reach, nor between planes in the wrong order.
  EXPECT_EQ(revolution_slab_volume(0.0, 0.6, 0.0, L, constant, 1.0, 2.0), 0.0);
  EXPECT_EQ(revolution_slab_volume(0.0, 0.6, 0.0, L, constant, 0.3, -0.3), 0.0);
}
