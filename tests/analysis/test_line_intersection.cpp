#include "analysis/line_intersection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/random.hpp"

using namespace bedforge;
using namespace bedforge::analysis;

TEST(LineIntersection, ArcLengthMatchesPointsOnTheCircle) {
  // Every case of Abreu et al.'s Fig. 2 (disk outside, inside, holding the circle, partial
  // with the circle smaller or larger than the disk) against counting points of the circle.
  Rng rng(2);
  for (int t = 0; t < 300; ++t) {
    const double rho = 0.05 + 3.0 * rng.uniform(), r = 0.1 + 1.5 * rng.uniform();
    const double s = 3.0 * rng.uniform(), phi = 6.0 * rng.uniform(), dz = r * (2.0 * rng.uniform() - 1.0);
    const Eigen::Vector3d c(s * std::cos(phi), s * std::sin(phi), 0.0);
    const int n = 20000;
    int inside = 0;
    for (int k = 0; k < n; ++k) {
      const double a = 2.0 * std::numbers::pi * (k + 0.5) / n;
      if ((Eigen::Vector3d(rho * std::cos(a), rho * std::sin(a), dz) - c).norm() < r) ++inside;
    }
    const double expected = 2.0 * std::numbers::pi * rho * inside / n;
    EXPECT_NEAR(circle_length_in_sphere(rho, dz, c, r), expected, 2.0 * std::numbers::pi * rho * 2.0 / n)
        << "rho " << rho << " r " << r << " s " << s << " dz " << dz;
  }
}

TEST(LineIntersection, AgreesWithVolumeIntersectionOnFineShells) {
  // Random non-overlapping spheres in a cylinder of radius 5: with thin shells the line
  // through a shell's middle and the shell's volume see the same solid (Abreu et al., Fig. 3).
  Bed bed;
  bed.container = std::make_shared<Cylinder>(5.0);
  Rng rng(6);
  while (bed.size() < 300) {
    const Eigen::Vector2d xy = bed.container->sample_centre(rng, 0.5);
    const Eigen::Vector3d p(xy.x(), xy.y(), 0.5 + 9.0 * rng.uniform());
    bool free = true;
    for (const auto& q : bed.centres) free = free && (p - q).norm() >= 1.0;
    if (free) bed.centres.push_back(p), bed.diameters.push_back(1.0);
  }
  const Profile vol = radial_void_fraction(bed, 5.0, 0.0, 0.025, 2.0, 8.0);
  const Profile line = line_radial_void_fraction(bed, 5.0, 0.0, 0.025, 2.0, 8.0, 0.005);
  ASSERT_EQ(vol.position.size(), line.position.size());
  double mean_diff = 0.0;
  for (size_t k = 0; k < vol.position.size(); ++k) {
    EXPECT_NEAR(line.position[k], vol.position[k], 1e-12);
    EXPECT_NEAR(line.void_fraction[k], vol.void_fraction[k], 0.03) << "bin " << k;
    mean_diff += std::abs(line.void_fraction[k] - vol.void_fraction[k]) / vol.position.size();
  }
  EXPECT_LT(mean_diff, 0.005);
}
