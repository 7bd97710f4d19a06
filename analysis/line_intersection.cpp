#include "analysis/line_intersection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/parallel.hpp"

namespace bedforge::analysis {

double circle_length_in_sphere(double rho, double z, const Eigen::Vector3d& c, double r) {
  const double h2 = r * r - (z - c.z()) * (z - c.z());
  if (h2 <= 0.0) return 0.0;
  const double a = std::sqrt(h2), s = std::hypot(c.x(), c.y());
  if (rho >= s + a || rho <= s - a) return 0.0;          // Figs. 2a, 2b: the circle misses the disk
  if (rho + s <= a) return 2.0 * std::numbers::pi * rho;  // Fig. 2c: the disk holds the whole circle
  const double cos_t = std::clamp((rho * rho + s * s - a * a) / (2.0 * rho * s), -1.0, 1.0);
  return 2.0 * rho * std::acos(cos_t);  // Figs. 2d-2f
}

Profile line_radial_void_fraction(const Bed& bed, double wall, double end, double bin, double z1, double z2, double dz) {
  const double span = std::abs(end - wall), dir = end < wall ? -1.0 : 1.0;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(span / bin - 1e-9));
  const std::size_t steps = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((z2 - z1) / dz)));
  const double h = (z2 - z1) / static_cast<double>(steps);
  std::vector<double> rho(bins);
  for (std::size_t k = 0; k < bins; ++k) rho[k] = wall + dir * std::min(span, (k + 0.5) * bin);
  // Solid fraction of each circle, summed over the z samples.
  const auto covered = accumulate_bins(bed.size(), bins, [&](std::size_t i, std::vector<double>& acc) {
    const Eigen::Vector3d& c = bed.centres[i];
    const double r = 0.5 * bed.diameters[i], s = std::hypot(c.x(), c.y());
    const double lo = std::max(z1, c.z() - r), hi = std::min(z2, c.z() + r);
    if (lo >= hi) return;
    for (auto m = static_cast<std::size_t>(std::max(0.0, std::floor((lo - z1) / h))); m < steps; ++m) {
      const double z = z1 + (static_cast<double>(m) + 0.5) * h;
      if (z > hi) break;
      for (std::size_t k = 0; k < bins; ++k)
        if (std::abs(rho[k] - s) < r && rho[k] > 0.0)
          acc[k] += circle_length_in_sphere(rho[k], z, c, r) / (2.0 * std::numbers::pi * rho[k]);
    }
  });
  Profile p;
  for (std::size_t k = 0; k < bins; ++k) {
    p.position.push_back(std::abs(rho[k] - wall));
    p.void_fraction.push_back(1.0 - covered[k] / static_cast<double>(steps));
  }
  return p;
}

}  // namespace bedforge::analysis
