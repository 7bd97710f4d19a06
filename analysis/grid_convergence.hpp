#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace bedforge::analysis {

// One mesh of a grid-convergence study: its representative cell size h = (V / N)^(1/3) (m, V
// the domain's volume, N its cells) and the quantity phi computed on it (e.g. dp/L, Pa/m).
struct GridLevel {
  double cell_size = 0.0;
  double value = 0.0;
};

// The verdict of Celik et al. (2008, J. Fluids Eng. 130, 078001) on three meshes, the
// Richardson extrapolation and the grid convergence index of Roache (1994).
struct GridConvergence {
  enum class Verdict {
    monotone,     // s > 0 and a positive order: p, phi_ext and the GCI apply
    oscillatory,  // e32 and e21 of opposite signs: no extrapolation
    divergent,    // |e32 / e21| <= ln r32 / ln r21 (1 for equal ratios): no positive order
    unresolved,   // e21 = 0 or e32 = 0 to round-off: nothing to extrapolate from
  };
  Verdict verdict = Verdict::unresolved;
  double r21 = 0.0, r32 = 0.0;      // refinement ratios h2/h1, h3/h2
  double order = 0.0;               // apparent order p (NaN unless monotone)
  double extrapolated = 0.0;        // phi_ext (NaN unless monotone)
  double relative_error_fine = 0.0; // e_a21 = |(phi1 - phi2) / phi1|
  double extrapolated_error_fine = 0.0;  // e_ext21 = |(phi_ext - phi1) / phi_ext|
  double gci_fine = 0.0;            // GCI_21 = 1.25 e_a21 / (r21^p - 1), relative
  double gci_medium = 0.0;          // GCI_32, for the asymptotic-range check
  double asymptotic_ratio = 0.0;    // GCI_32 / (r21^p GCI_21): near 1 in the asymptotic range
  // Monotone and the order within kAsymptoticOrder: only then do phi_ext and the GCI mean much
  // (an order far from the formal one says the meshes are not in the asymptotic range,
  // verification.md after Celik et al.).
  bool asymptotic = false;
  std::string explanation;          // one sentence a report can show
  nlohmann::json to_json() const;
};

// The apparent orders taken as the asymptotic range of OpenFOAM's second-order schemes: half to
// one and a half times the formal order 2 (the range issue 24 accepts for the observed order).
inline constexpr double kAsymptoticOrder[2] = {1.0, 3.0};

const char* verdict_name(GridConvergence::Verdict v);

// Applies the procedure to `levels` ordered fine (1), medium (2), coarse (3): the apparent order
// by fixed-point iteration on p = |ln|e32/e21| + q(p)| / ln r21, q(p) = ln((r21^p - s)/(r32^p - s)).
// std::invalid_argument unless there are exactly three levels, each coarser than the one before
// (cell sizes strictly increasing) and all values finite.
GridConvergence grid_convergence(const std::vector<GridLevel>& levels);

// The power law phi = phi0 + alpha h^p fitted to four or more levels by least squares: the
// "delta_RE" fit of Eca & Hoekstra (2014, J. Comput. Phys. 262, 104), whose scatter shows what
// three levels cannot: how far the levels themselves stray from one power law. For each order p
// the best phi0 and alpha are linear; p is searched over [kFitOrders[0], kFitOrders[1]].
struct PowerLawFit {
  bool fitted = false;         // the values change one way and the least-squares order lies
                               // inside the range searched
  int levels = 0;              // the levels fitted
  double order = 0.0;          // p (NaN unless fitted)
  double extrapolated = 0.0;   // phi0 (NaN unless fitted)
  double coefficient = 0.0;    // alpha of phi0 + alpha (h / h_1)^p, h_1 the finest (NaN unless fitted)
  double residual_sd = 0.0;    // sqrt(sum of squared residuals / (levels - 3)), phi's unit
  double largest_residual = 0.0;  // max |phi_i - fit(h_i)|, phi's unit
  // Fitted and the order within kAsymptoticOrder, the rule the three-level procedure applies: a
  // small scatter does not make an order outside it trustworthy (docs/findings.md, session 29).
  bool asymptotic = false;
  std::string explanation;     // one sentence a report can show
  nlohmann::json to_json() const;
};

// The orders fit_power_law searches: wide enough that an order at either end means no fit.
inline constexpr double kFitOrders[2] = {0.05, 8.0};

// std::invalid_argument unless there are at least four levels, each coarser than the one
// before, all values finite.
PowerLawFit fit_power_law(const std::vector<GridLevel>& levels);

// Verification against a known answer: the order p of the error |phi / exact - 1| ~ C h^p, by
// least squares on ln error against ln h over `levels` (any order, two or more with distinct
// sizes). NaN when fewer than two levels have a nonzero error, or when the errors change sign:
// levels on both sides of the exact value follow no C h^p, and a fit of |error| would report
// the crossing as a high order.
double observed_order(const std::vector<GridLevel>& levels, double exact);

}  // namespace bedforge::analysis
