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

// Area of the part of a disk of radius R whose signed distance s from its centre along one
// direction is at most `s` (0 below -R, the whole disk above R).
double disk_below(double R, double s) {
  if (R <= 0.0 || s <= -R) return 0.0;
  if (s >= R) return kPi * R * R;
  const double u = s / R;
  return R * R * (std::asin(u) + 0.5 * kPi + u * std::sqrt(1.0 - u * u));
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

double revolution_slab_volume(double origin_z, double axis_z, double t0, double t1,
                              const std::function<double(double)>& radius, double z1, double z2) {
  if (!(t1 > t0) || !(z2 > z1)) return 0.0;
  const double a = std::clamp(axis_z, -1.0, 1.0);
  // Across the disk's plane z changes by `slope` per unit length along its steepest line.
  const double slope = std::sqrt(std::max(0.0, 1.0 - a * a));
  auto centre_z = [&](double t) { return origin_z + t * a; };
  auto area = [&](double t) {
    const double R = std::max(0.0, radius(t)), zc = centre_z(t);
    if (slope < 1e-12) return zc >= z1 && zc <= z2 ? kPi * R * R : 0.0;  // a disk in a horizontal plane
    return disk_below(R, (z2 - zc) / slope) - disk_below(R, (z1 - zc) / slope);
  };
  // Splits: where a plane meets the disk's rim, (z - zc(t))^2 = (R(t) slope)^2, found by sign
  // changes on a fine sampling then bisection; and where it passes the centre of a horizontal disk.
  std::vector<double> cuts = {t0, t1};
  constexpr int kSamples = 64;
  for (double z : {z1, z2}) {
    auto rim = [&](double t) {
      const double dz = z - centre_z(t), reach = std::max(0.0, radius(t)) * slope;
      return dz * dz - reach * reach;
    };
    double prev_t = t0, prev = rim(t0);
    for (int k = 1; k <= kSamples; ++k) {
      const double t = t0 + (t1 - t0) * k / kSamples, g = rim(t);
      if ((prev < 0.0) != (g < 0.0)) {
        double lo = prev_t, hi = t;
        for (int it = 0; it < 60; ++it) {
          const double mid = 0.5 * (lo + hi);
          ((rim(mid) < 0.0) == (prev < 0.0) ? lo : hi) = mid;
        }
        cuts.push_back(0.5 * (lo + hi));
      }
      prev_t = t, prev = g;
    }
    if (a != 0.0)
      if (const double t = (z - origin_z) / a; t > t0 && t < t1) cuts.push_back(t);
  }
  // Each piece through t = c + (3u^2 - 2u^3) (c' - c), whose derivative vanishes at both ends:
  // the kinks there ((t - c)^(3/2)) become smooth enough for Gauss-Legendre.
  std::sort(cuts.begin(), cuts.end());
  double v = 0.0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double c = cuts[k], span = cuts[k + 1] - cuts[k];
    v += integrate_pieces({0.0, 1.0}, [&](double u) { return area(c + span * u * u * (3.0 - 2.0 * u)) * span * 6.0 * u * (1.0 - u); });
  }
  return v;
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
