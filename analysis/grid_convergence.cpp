#include "analysis/grid_convergence.hpp"

#include <fmt/format.h>

#include <algorithm>
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

nlohmann::json PowerLawFit::to_json() const {
  auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  return {{"fitted", fitted},
          {"levels", levels},
          {"order", number(order)},
          {"extrapolated", number(extrapolated)},
          {"coefficient", number(coefficient)},
          {"residual_sd", number(residual_sd)},
          {"largest_residual", number(largest_residual)},
          {"asymptotic", asymptotic},
          {"explanation", explanation}};
}

namespace {

// The sums of a least-squares line y = a + b x through points added one by one.
struct LineSums {
  double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  void add(double x, double y) { n += 1.0, sx += x, sy += y, sxx += x * x, sxy += x * y; }
  double determinant() const { return n * sxx - sx * sx; }
  double slope() const { return (n * sxy - sx * sy) / determinant(); }
  double intercept() const { return (sy - slope() * sx) / n; }
};

// The least-squares phi0 and alpha of phi = phi0 + alpha x for x_i = (h_i / h_1)^p, the sum of
// squared residuals and the largest residual.
struct LinearFit {
  double phi0 = 0.0, alpha = 0.0, squares = 0.0, largest = 0.0;
};
LinearFit fit_at_order(const std::vector<GridLevel>& levels, double p) {
  LineSums line;
  for (const GridLevel& l : levels) line.add(std::pow(l.cell_size / levels.front().cell_size, p), l.value);
  LinearFit f;
  f.alpha = line.slope();
  f.phi0 = line.intercept();
  for (const GridLevel& l : levels) {
    const double r = l.value - f.phi0 - f.alpha * std::pow(l.cell_size / levels.front().cell_size, p);
    f.squares += r * r;
    f.largest = std::max(f.largest, std::abs(r));
  }
  return f;
}

}  // namespace

PowerLawFit fit_power_law(const std::vector<GridLevel>& levels) {
  if (levels.size() < 4)
    throw std::invalid_argument(fmt::format("a least-squares power law needs at least 4 meshes, got {}", levels.size()));
  for (std::size_t i = 0; i < levels.size(); ++i) {
    if (!std::isfinite(levels[i].cell_size) || !std::isfinite(levels[i].value) || !(levels[i].cell_size > 0.0))
      throw std::invalid_argument("least-squares power law: a cell size or value is not a finite number");
    if (i > 0 && !(levels[i].cell_size > levels[i - 1].cell_size))
      throw std::invalid_argument("least-squares power law: the meshes must go from fine to coarse (cell sizes increasing)");
  }
  PowerLawFit f;
  f.levels = static_cast<int>(levels.size());
  f.order = f.extrapolated = f.coefficient = f.residual_sd = f.largest_residual =
      std::numeric_limits<double>::quiet_NaN();
  // A power law changes one way: values that turn back are oscillation, which no order fits.
  for (std::size_t i = 2; i < levels.size(); ++i)
    if ((levels[i].value - levels[i - 1].value) * (levels[i - 1].value - levels[i - 2].value) <= 0.0) {
      f.explanation = fmt::format("the {} levels' values do not change one way as the mesh refines: no power law fits "
                                  "them",
                                  f.levels);
      return f;
    }
  // The sum of squares over p: scanned on a geometric grid, then its least sample's bracket
  // narrowed by golden sections.
  const int samples = 400;
  const double step = std::log(kFitOrders[1] / kFitOrders[0]) / samples;
  auto order_at = [&](int k) { return kFitOrders[0] * std::exp(step * k); };
  int best = 0;
  double least = fit_at_order(levels, order_at(0)).squares;
  for (int k = 1; k <= samples; ++k)
    if (const double squares = fit_at_order(levels, order_at(k)).squares; squares < least) best = k, least = squares;
  if (best == 0 || best == samples) {
    f.explanation = fmt::format("no power law fits the {} levels with an order between {:g} and {:g} (the best lies at "
                                "the range's end): they do not converge like one",
                                f.levels, kFitOrders[0], kFitOrders[1]);
    return f;
  }
  double lo = order_at(best - 1), hi = order_at(best + 1);
  const double golden = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int it = 0; it < 100 && hi - lo > 1e-10 * hi; ++it) {
    const double a = hi - golden * (hi - lo), b = lo + golden * (hi - lo);
    if (fit_at_order(levels, a).squares < fit_at_order(levels, b).squares)
      hi = b;
    else
      lo = a;
  }
  const double p = 0.5 * (lo + hi);
  const LinearFit lin = fit_at_order(levels, p);
  f.fitted = true;
  f.order = p;
  f.extrapolated = lin.phi0;
  f.coefficient = lin.alpha;
  f.residual_sd = std::sqrt(lin.squares / static_cast<double>(f.levels - 3));
  f.largest_residual = lin.largest;
  f.explanation = fmt::format("over {} levels by least squares (Eca & Hoekstra 2014): order {:.2f}, extrapolated {:.6g}, "
                              "the levels {:.2g} % from the fit at most (standard deviation {:.2g} %)",
                              f.levels, p, lin.phi0, 100.0 * f.largest_residual / std::abs(lin.phi0),
                              100.0 * f.residual_sd / std::abs(lin.phi0));
  f.asymptotic = p >= kAsymptoticOrder[0] && p <= kAsymptoticOrder[1];
  if (!f.asymptotic)
    f.explanation += fmt::format(", but that order is outside {:g}-{:g}: the levels are not in the asymptotic range, so the "
                                 "extrapolation cannot be trusted",
                                 kAsymptoticOrder[0], kAsymptoticOrder[1]);
  return f;
}

double observed_order(const std::vector<GridLevel>& levels, double exact) {
  LineSums line;
  bool above = false, below = false;
  for (const GridLevel& l : levels) {
    const double signed_error = l.value / exact - 1.0, e = std::abs(signed_error);
    above = above || signed_error > 0.0;
    below = below || signed_error < 0.0;
    if (e > 0.0 && l.cell_size > 0.0) line.add(std::log(l.cell_size), std::log(e));
  }
  if (line.n < 2.0 || !(line.determinant() > 0.0) || (above && below)) return std::numeric_limits<double>::quiet_NaN();
  return line.slope();
}

}  // namespace bedforge::analysis
