#include "analysis/stokes_arrays.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace bedforge::analysis {

namespace {
const double kPi = std::acos(-1.0);
}  // namespace

std::optional<double> zick_homsy_simple_cubic(double solid_fraction) {
  // (phi, K), Zick & Homsy (1982), Table 2, simple cubic array.
  static constexpr std::array<std::pair<double, double>, 7> kTable{
      {{0.027, 2.008}, {0.064, 2.810}, {0.125, 4.292}, {0.216, 7.442}, {0.343, 15.4}, {0.45, 28.1}, {0.5236, 42.1}}};
  for (const auto& [phi, k] : kTable)
    if (std::abs(solid_fraction / phi - 1.0) <= 1e-4) return k;
  return std::nullopt;
}

std::optional<double> simple_cubic_column_gradient(const Bed& bed, double viscosity, double velocity, double z_low,
                                                   double z_high) {
  const auto* box = dynamic_cast<const Box*>(bed.container.get());
  if (!box || bed.centres.empty() || box->periodicity().lateral()) return std::nullopt;
  const double L = box->size_x(), tolerance = 1e-6 * L, d = bed.diameters.front();
  if (std::abs(box->size_y() - L) > tolerance) return std::nullopt;
  std::vector<Eigen::Vector3d> centres = bed.centres;  // in any order
  std::sort(centres.begin(), centres.end(), [](const auto& a, const auto& b) { return a.z() < b.z(); });
  for (size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d expected(0.0, 0.0, (static_cast<double>(i) + 0.5) * L);
    if ((centres[i] - expected).norm() > tolerance || std::abs(bed.diameters[i] - d) > tolerance) return std::nullopt;
  }
  const double cells = (z_high - z_low) / L;
  if (cells < 0.5 || std::abs(cells - std::round(cells)) > 1e-6) return std::nullopt;
  const std::optional<double> k = zick_homsy_simple_cubic(kPi * d * d * d / (6.0 * L * L * L));
  if (!k) return std::nullopt;
  return 3.0 * kPi * viscosity * d * *k * velocity / (L * L * L);
}

std::optional<double> simple_cubic_array_gradient(const Bed& bed, double viscosity, double velocity) {
  const Periodicity per = bed.container->periodicity();
  if (bed.centres.empty() || !dynamic_cast<const Box*>(bed.container.get()) || !(per.lx > 0.0 && per.ly > 0.0 && per.lz > 0.0))
    return std::nullopt;
  const double side = per.lx, d = bed.diameters.front();
  const long m = std::lround(std::cbrt(static_cast<double>(bed.size())));
  const double L = side / static_cast<double>(m), tolerance = 1e-6 * L;
  if (m * m * m != static_cast<long>(bed.size()) || std::abs(per.ly - side) > tolerance || std::abs(per.lz - side) > tolerance)
    return std::nullopt;
  // Every centre a lattice point from the first: its offset from it a whole number of spacings.
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const Eigen::Vector3d steps = (bed.centres[i] - bed.centres[0]) / L;
    if ((steps - steps.array().round().matrix()).norm() * L > tolerance || std::abs(bed.diameters[i] - d) > tolerance)
      return std::nullopt;
  }
  const std::optional<double> k = zick_homsy_simple_cubic(kPi * d * d * d / (6.0 * L * L * L));
  if (!k) return std::nullopt;
  return 3.0 * kPi * viscosity * d * *k * velocity / (L * L * L);
}

}  // namespace bedforge::analysis
