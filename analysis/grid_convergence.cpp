#include "analysis/grid_convergence.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace bedforge::analysis {

const char* verdict_name(GridConvergence::Verdict v) {
  switch (v) {
    case GridConvergence::Verdict::monotone: return "monotone";
    case GridConvergence::Verdict::oscillatory: return "oscillatory";
    case GridConvergence::Verdict::divergent: return "divergent";
    case GridConvergence::Verdict::unresolved: break;
  }
  return "unresolved";
}

nlohmann::json GridConvergence::to_json() const {
  auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  return {{"verdict", verdict_name(verdict)},
          {"refinement_ratio_21", r21},
          {"refinement_ratio_32", r32},
          {"apparent_order", number(order)},
          {"extrapolated", number(extrapolated)},
          {"relative_error_fine", relative_error_fine},
          {"extrapolated_error_fine", number(extrapolated_error_fine)},
          {"gci_fine", number(gci_fine)},
          {"gci_medium", number(gci_medium)},
          {"asymptotic_ratio", number(asymptotic_ratio)},
          {"asymptotic", asymptotic},
          {"explanation", explanation}};
}

GridConvergence grid_convergence(const std::vector<GridLevel>& levels) {
  if (levels.size() != 3)
    throw std::invalid_argument(fmt::format("grid convergence needs 3 meshes, got {}", levels.size()));
  for (const GridLevel& l : levels)
    if (!std::isfinite(l.cell_size) || !std::isfinite(l.value) || !(l.cell_size > 0.0))
      throw std::invalid_argument("grid convergence: a cell size or value is not a finite number");
  if (!(levels[1].cell_size > levels[0].cell_size && levels[2].cell_size > levels[1].cell_size))
    throw std::invalid_argument("grid convergence: the meshes must go from fine to coarse (cell sizes increasing)");

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double phi1 = levels[0].value, phi2 = levels[1].value, phi3 = levels[2].value;
  GridConvergence g;
  g.r21 = levels[1].cell_size / levels[0].cell_size;
  g.r32 = levels[2].cell_size / levels[1].cell_size;
  g.order = g.extrapolated = g.extrapolated_error_fine = g.gci_fine = g.gci_medium = g.asymptotic_ratio = nan;
  const double e21 = phi2 - phi1, e32 = phi3 - phi2;
  g.relative_error_fine = std::abs(e21 / phi1);
  const double scale = std::max({std::abs(phi1), std::abs(phi2), std::abs(phi3)});
  const double round_off = 64.0 * std::numeric_limits<double>::epsilon() * scale;
  if (std::abs(e21) <= round_off || std::abs(e32) <= round_off) {
    g.verdict = GridConvergence::Verdict::unresolved;
    g.explanation = "two meshes give the same value to round-off: no order can be measured";
    return g;
  }
  if (e32 / e21 < 0.0) {
    g.verdict = GridConvergence::Verdict::oscillatory;
    g.explanation = fmt::format("the value oscillates as the mesh refines ({:.6g}, {:.6g}, {:.6g} coarse to fine): "
                                "not in the asymptotic range, no extrapolation",
                                phi3, phi2, phi1);
    return g;
  }
  // On a power law phi0 + C h^p, |e32 / e21| = r21^p (r32^p - 1) / (r21^p - 1), which rises
  // with p from ln r32 / ln r21 at p = 0 (r^p for equal ratios): a positive order needs more.
  const double zero_order = std::log(g.r32) / std::log(g.r21);
  if (std::abs(e32 / e21) <= zero_order) {
    g.verdict = GridConvergence::Verdict::divergent;
    g.explanation = fmt::format("the change does not shrink as the mesh refines (|e32 / e21| = {:.3g}, at most {:.3g} "
                                "for these ratios): not converging, no extrapolation",
                                std::abs(e32 / e21), zero_order);
    return g;
  }
  // Monotone convergence (s = 1): fixed-point iteration for the apparent order.
  const double ln21 = std::log(g.r21), ratio = std::log(std::abs(e32 / e21));
  double p = ratio / ln21;  // the equal-ratio value, q = 0
  for (int it = 0; it < 200; ++it) {
    const double q = std::log((std::pow(g.r21, p) - 1.0) / (std::pow(g.r32, p) - 1.0));
    const double next = std::abs(ratio + q) / ln21;
    const bool done = std::abs(next - p) <= 1e-12 * std::max(1.0, p);
    p = next;
    if (done) break;
  }
  g.verdict = GridConvergence::Verdict::monotone;
  g.order = p;
  const double r21p = std::pow(g.r21, p), r32p = std::pow(g.r32, p);
  g.extrapolated = (r21p * phi1 - phi2) / (r21p - 1.0);
  g.extrapolated_error_fine = std::abs((g.extrapolated - phi1) / g.extrapolated);
  g.gci_fine = 1.25 * g.relative_error_fine / (r21p - 1.0);
  g.gci_medium = 1.25 * std::abs(e32 / phi2) / (r32p - 1.0);
  g.asymptotic_ratio = g.gci_medium / (r21p * g.gci_fine);
  g.asymptotic = p >= kAsymptoticOrder[0] && p <= kAsymptoticOrder[1];
  g.explanation = fmt::format("monotone convergence at apparent order {:.2f}; extrapolated {:.6g}, GCI of the finest "
                              "mesh {:.2g} %",
                              p, g.extrapolated, 100.0 * g.gci_fine);
  if (!g.asymptotic)
    g.explanation += fmt::format(", but that order is far from the schemes' formal 2 (outside {:g}-{:g}): the meshes are "
                                 "not in the asymptotic range, so neither the extrapolation nor the GCI can be trusted",
                                 kAsymptoticOrder[0], kAsymptoticOrder[1]);
  return g;
}

double observed_order(const std::vector<GridLevel>& levels, double exact) {
  double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (const GridLevel& l : levels) {
    const double e = std::abs(l.value / exact - 1.0);
    if (!(e > 0.0) || !(l.cell_size > 0.0)) continue;
    const double x = std::log(l.cell_size), y = std::log(e);
    n += 1.0, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double det = n * sxx - sx * sx;
  if (n < 2.0 || !(det > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (n * sxy - sx * sy) / det;
}

}  // namespace bedforge::analysis
