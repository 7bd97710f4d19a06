#include "analysis/segregation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/intersection_volumes.hpp"

namespace bedforge::analysis {

Segregation axial_segregation(const Bed& bed, double layer, double top, std::size_t max_species) {
  Segregation out;
  std::vector<double> sizes = bed.diameters;
  std::sort(sizes.begin(), sizes.end(), std::greater<>());
  for (double d : sizes)
    if (out.diameters.empty() || std::abs(out.diameters.back() - d) > 1e-9 * d) out.diameters.push_back(d);
  if (out.diameters.size() < 2 || out.diameters.size() > max_species) return {};
  auto species_of = [&](double d) {
    std::size_t k = 0;
    while (std::abs(out.diameters[k] - d) > 1e-9 * d) ++k;
    return k;
  };

  const std::size_t layers = static_cast<std::size_t>(std::ceil(top / layer - 1e-9));
  const std::size_t ns = out.diameters.size();
  std::vector<std::vector<double>> solid(ns, std::vector<double>(layers, 0.0));
  std::vector<double> mass_z(ns, 0.0), mass(ns, 0.0);
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const std::size_t s = species_of(bed.diameters[i]);
    const double r = 0.5 * bed.diameters[i], z = bed.centres[i].z(), v = r * r * r;
    mass_z[s] += v * z, mass[s] += v;
    for (auto k = static_cast<std::size_t>(std::max(0.0, std::floor((z - r) / layer)));
         k < layers && static_cast<double>(k) * layer < z + r; ++k)
      solid[s][k] += sphere_slab_volume(r, z, static_cast<double>(k) * layer, std::min(top, (k + 1.0) * layer));
  }
  const double area = bed.container->cross_section_area();
  out.volume_fraction.assign(ns, std::vector<double>(layers, 0.0));
  double total_a = 0.0, total = 0.0;
  for (std::size_t k = 0; k < layers; ++k) {
    const double lo = static_cast<double>(k) * layer, hi = std::min(top, lo + layer);
    out.z.push_back(0.5 * (lo + hi));
    for (std::size_t s = 0; s < ns; ++s) {
      out.volume_fraction[s][k] = solid[s][k] / (area * (hi - lo));
      total += solid[s][k];
    }
    total_a += solid[0][k];
  }
  const double c = total > 0.0 ? total_a / total : 0.0;
  double num = 0.0;
  for (std::size_t k = 0; k < layers; ++k) {
    double v = 0.0;
    for (std::size_t s = 0; s < ns; ++s) v += solid[s][k];
    if (v > 0.0) num += v * std::pow(solid[0][k] / v - c, 2);
  }
  out.intensity = c > 0.0 && c < 1.0 ? num / (total * c * (1.0 - c)) : 0.0;
  for (std::size_t s = 0; s < ns; ++s) out.mean_height.push_back(mass[s] > 0.0 ? mass_z[s] / mass[s] : 0.0);
  return out;
}

}  // namespace bedforge::analysis
