#include "core/intersection_volumes.hpp"

#include "core/quadrature.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace bedforge {

namespace {

constexpr double kPi = std::numbers::pi;

// Volume of the part of a sphere of radius r below height h above its lowest point.
double cap_below(double r, double h) {
  h = std::clamp(h, 0.0, 2.0 * r);
  return kPi * h * h * (3.0 * r - h) / 3.0;
}


}  // namespace

double sphere_slab_volume(double r, double zc, double z1, double z2) {
  if (z2 <= z1) return 0.0;
  const double bottom = zc - r;
  return cap_below(r, z2 - bottom) - cap_below(r, z1 - bottom);
}

double disk_lens_area(double a, double s, double rho) {
  if (a <= 0.0 || rho <= 0.0) return 0.0;
  if (s >= a + rho) return 0.0;
  if (s <= std::abs(rho - a)) {
    const double m = std::min(a, rho);
    return kPi * m * m;
  }
  const double c1 = std::clamp((s * s + a * a - rho * rho) / (2.0 * s * a), -1.0, 1.0);
  const double c2 = std::clamp((s * s + rho * rho - a * a) / (2.0 * s * rho), -1.0, 1.0);
  const double k = (-s + a + rho) * (s + a - rho) * (s - a + rho) * (s + a + rho);
  return a * a * std::acos(c1) + rho * rho * std::acos(c2) - 0.5 * std::sqrt(std::max(0.0, k));
}

double sphere_cylinder_volume(double r, double s, double zc, double rho, double z1, double z2) {
  const double lo = std::max(z1, zc - r), hi = std::min(z2, zc + r);
  if (hi <= lo || rho <= 0.0) return 0.0;
  if (s + r <= rho) return sphere_slab_volume(r, zc, lo, hi);  // wholly inside
  if (s >= r + rho) return 0.0;                                 // wholly outside
  // The lens changes form where the section radius a(z) = sqrt(r^2 - (z - zc)^2) equals
  // |rho - s| or rho + s; split there.
  std::vector<double> cuts = {lo, hi};
  for (double c : {std::abs(rho - s), rho + s})
    if (c < r) {
      const double h = std::sqrt(r * r - c * c);
      for (double z : {zc - h, zc + h})
        if (z > lo && z < hi) cuts.push_back(z);
    }
  if (zc > lo && zc < hi) cuts.push_back(zc);
  return integrate_pieces(std::move(cuts), [&](double z) {
    return disk_lens_area(std::sqrt(std::max(0.0, r * r - (z - zc) * (z - zc))), s, rho);
  });
}

double sphere_halfspace_volume(double r, double xc, double zc, double x_max, double z1, double z2) {
  const double lo = std::max(z1, zc - r), hi = std::min(z2, zc + r);
  if (hi <= lo) return 0.0;
  const double t0 = x_max - xc;
  if (t0 >= r) return sphere_slab_volume(r, zc, lo, hi);  // wholly on the kept side
  if (t0 <= -r) return 0.0;
  // The segment of the section disk (radius a) left of the line vanishes or fills the disk
  // where a = |x_max - xc|; split there and at the equator.
  std::vector<double> cuts = {lo, hi};
  const double h = std::sqrt(r * r - t0 * t0);
  for (double z : {zc - h, zc + h, zc})
    if (z > lo && z < hi) cuts.push_back(z);
  return integrate_pieces(std::move(cuts), [&](double z) {
    const double a2 = std::max(0.0, r * r - (z - zc) * (z - zc)), a = std::sqrt(a2);
    if (a <= 0.0) return 0.0;
    const double t = std::clamp(t0 / a, -1.0, 1.0);
    return a2 * (std::numbers::pi - std::acos(t) + t * std::sqrt(1.0 - t * t));  // disk minus the cap beyond x_max
  });
}

}  // namespace bedforge
