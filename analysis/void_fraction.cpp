#include "analysis/void_fraction.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/intersection_volumes.hpp"
#include "core/parallel.hpp"

namespace bedforge::analysis {

double void_fraction(const Bed& bed, double z1, double z2) {
  const auto solid = accumulate_bins(bed.size(), 1, [&](std::size_t i, std::vector<double>& acc) {
    acc[0] += sphere_slab_volume(0.5 * bed.diameters[i], bed.centres[i].z(), z1, z2);
  });
  return 1.0 - solid[0] / (bed.container->cross_section_area() * (z2 - z1));
}

Profile radial_void_fraction(const Bed& bed, double wall, double end, double bin, double z1, double z2) {
  const double span = std::abs(end - wall), dir = end < wall ? -1.0 : 1.0;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(span / bin - 1e-9));
  // Edge k is the coaxial cylinder at distance k bin from the wall; the last edge is `end`.
  auto edge = [&](std::size_t k) { return wall + dir * std::min(span, static_cast<double>(k) * bin); };
  const auto solid = accumulate_bins(bed.size(), bins, [&](std::size_t i, std::vector<double>& acc) {
    const double r = 0.5 * bed.diameters[i];
    const auto& c = bed.centres[i];
    const double s = std::hypot(c.x(), c.y());
    if (c.z() + r <= z1 || c.z() - r >= z2) return;
    // Volume of the sphere's slab part inside the cylinder of radius rho; shells are differences
    // of it, so they add up to the sphere's slab volume exactly.
    const double whole = sphere_slab_volume(r, c.z(), z1, z2);
    auto inside = [&](double rho) {
      if (rho <= s - r) return 0.0;
      if (rho >= s + r) return whole;
      return sphere_cylinder_volume(r, s, c.z(), rho, z1, z2);
    };
    double prev = inside(edge(0));
    for (std::size_t k = 0; k < bins; ++k) {
      const double lo = std::min(edge(k), edge(k + 1)), hi = std::max(edge(k), edge(k + 1));
      if (hi <= s - r || lo >= s + r) {  // the shell misses the sphere
        prev = inside(edge(k + 1));
        continue;
      }
      const double next = inside(edge(k + 1));
      acc[k] += std::abs(prev - next);
      prev = next;
    }
  });
  Profile p;
  for (std::size_t k = 0; k < bins; ++k) {
    const double a = edge(k), b = edge(k + 1);
    const double shell = std::numbers::pi * std::abs(a * a - b * b) * (z2 - z1);
    p.position.push_back(0.5 * (a + b - 2.0 * wall) * dir);
    p.void_fraction.push_back(1.0 - solid[k] / shell);
  }
  return p;
}

Profile wall_void_fraction(const Bed& bed, int axis, double half_width, double other_width, double bin, double z1,
                           double z2) {
  const std::size_t bins = static_cast<std::size_t>(std::ceil(half_width / bin - 1e-9));
  auto edge = [&](std::size_t k) { return std::min(half_width, static_cast<double>(k) * bin); };
  const auto solid = accumulate_bins(bed.size(), bins, [&](std::size_t i, std::vector<double>& acc) {
    const double r = 0.5 * bed.diameters[i], zc = bed.centres[i].z();
    if (zc + r <= z1 || zc - r >= z2) return;
    // Distance of the centre from each wall; by symmetry both walls are the wall at 0.
    const double x = bed.centres[i][axis];
    for (double from_wall : {half_width + x, half_width - x}) {
      if (from_wall - r >= half_width) continue;
      double prev = 0.0;  // volume within distance edge(k) of this wall
      for (std::size_t k = 0; k < bins; ++k) {
        if (edge(k) >= from_wall + r) break;
        const double next = sphere_halfspace_volume(r, from_wall, zc, edge(k + 1), z1, z2);
        acc[k] += next - prev;
        prev = next;
      }
    }
  });
  Profile p;
  for (std::size_t k = 0; k < bins; ++k) {
    p.position.push_back(0.5 * (edge(k) + edge(k + 1)));
    p.void_fraction.push_back(1.0 - solid[k] / (2.0 * (edge(k + 1) - edge(k)) * other_width * (z2 - z1)));
  }
  return p;
}

Profile axial_void_fraction(const Bed& bed, double bin, double top) {
  const std::size_t bins = static_cast<std::size_t>(std::ceil(top / bin - 1e-9));
  const auto solid = accumulate_bins(bed.size(), bins, [&](std::size_t i, std::vector<double>& acc) {
    const double r = 0.5 * bed.diameters[i], z = bed.centres[i].z();
    const std::size_t first = static_cast<std::size_t>(std::max(0.0, std::floor((z - r) / bin)));
    for (std::size_t k = first; k < bins && static_cast<double>(k) * bin < z + r; ++k)
      acc[k] += sphere_slab_volume(r, z, static_cast<double>(k) * bin, std::min(top, static_cast<double>(k + 1) * bin));
  });
  Profile p;
  const double area = bed.container->cross_section_area();
  for (std::size_t k = 0; k < bins; ++k) {
    const double lo = static_cast<double>(k) * bin, hi = std::min(top, lo + bin);
    p.position.push_back(0.5 * (lo + hi));
    p.void_fraction.push_back(1.0 - solid[k] / (area * (hi - lo)));
  }
  return p;
}

CentreDistribution radial_centre_distribution(const Bed& bed, double wall, double end, double bin, double z1,
                                              double z2, double reachable_area) {
  const double span = std::abs(end - wall), dir = end < wall ? -1.0 : 1.0;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(span / bin - 1e-9));
  std::vector<double> count(bins, 0.0);
  double total = 0.0;
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const auto& c = bed.centres[i];
    if (c.z() < z1 || c.z() >= z2) continue;
    total += 1.0;
    const double x = dir * (std::hypot(c.x(), c.y()) - wall);  // distance from this wall
    if (x > span) continue;  // nearer the other wall: counted there
    count[std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, x) / bin))] += 1.0;
  }
  CentreDistribution out;
  const double mean_density = total / std::max(reachable_area, 1e-300);
  for (std::size_t k = 0; k < bins; ++k) {
    const double a = wall + dir * static_cast<double>(k) * bin, b = wall + dir * std::min(span, (k + 1.0) * bin);
    const double area = std::numbers::pi * std::abs(a * a - b * b);
    out.position.push_back(0.5 * (a + b - 2.0 * wall) * dir);
    out.fraction.push_back(total > 0 ? count[k] / total : 0.0);
    out.relative_density.push_back(total > 0 && area > 0 ? count[k] / area / mean_density : 0.0);
  }
  return out;
}

}  // namespace bedforge::analysis
