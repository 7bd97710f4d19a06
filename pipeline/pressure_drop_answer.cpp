#include "pipeline/pressure_drop_answer.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "analysis/pressure_drop.hpp"

namespace bedforge::pipeline {

namespace {

// The least-squares exponent k of time ~ cells^k over the levels that gave a value and were
// timed, within [0.5, 2] (1 when fewer than two such levels).
double time_exponent(const std::vector<StudyLevel>& levels) {
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  int n = 0;
  for (const StudyLevel& l : levels)
    if (l.failure.empty() && l.own_time_s > 0.0 && l.cells > 0) {
      const double x = std::log(static_cast<double>(l.cells)), y = std::log(l.own_time_s);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
  const double det = n * sxx - sx * sx;
  if (n < 2 || det <= 0.0) return 1.0;
  return std::clamp((n * sxy - sx * sy) / det, 0.5, 2.0);
}

// Text for an SVG document: its markup characters escaped.
std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '&' ? "&amp;" : c == '<' ? "&lt;" : c == '>' ? "&gt;" : std::string(1, c);
  return out;
}

std::string minutes(double s) { return s < 90.0 ? fmt::format("{:.0f} s", s) : fmt::format("{:.0f} min", s / 60.0); }

// The settings of a study one ratio finer, and what it would cost.
std::string finer_study_advice(const Scene& scene, const ConvergenceStudy& study, double solver_peak_mb) {
  const double ratio = scene.case_params.convergence.ratio;
  const FinerStudyCost cost = finer_study_cost(study, ratio, solver_peak_mb);
  const LevelLengths finer = level_lengths(scene, cost.scale);
  std::string keys = fmt::format("surface.edge_length_d = {:.3g}, surface.contact_edge_length_d = {:.3g}, "
                                 "mesh.max_size_d = {:.3g}",
                                 finer.surface.edge_length_d, finer.surface.contact_edge_length_d, finer.mesh.max_size_d);
  if (finer.surface.cells_per_gap > 0.0) keys += fmt::format(", surface.cells_per_gap = {:.3g}", finer.surface.cells_per_gap);
  if (finer.mesh.layers.count > 0) keys += fmt::format(", mesh.layers.thickness_d = {:.3g}", finer.mesh.layers.thickness_d);
  return fmt::format("refine every mesh length by the study's ratio {:g} ({}); by this study's levels its finest mesh "
                     "would have about {:.2g} cells and take about {} (surface, mesh and flow), the whole study about "
                     "{}, simpleFoam's processes about {:.1f} GB together",
                     ratio, keys, cost.cells, minutes(cost.finest_time_s), minutes(cost.study_time_s),
                     cost.peak_memory_mb / 1024.0);
}

}  // namespace

FinerStudyCost finer_study_cost(const ConvergenceStudy& study, double ratio, double solver_peak_memory_mb) {
  FinerStudyCost c;
  c.scale = 1.0 / ratio;
  const StudyLevel& finest = study.levels.front();
  const double cells_ratio = ratio * ratio * ratio;
  c.cells = static_cast<double>(finest.cells) * cells_ratio;
  c.finest_time_s = finest.own_time_s * std::pow(cells_ratio, time_exponent(study.levels));
  c.study_time_s = c.finest_time_s;
  for (std::size_t k = 0; k + 1 < study.levels.size(); ++k) c.study_time_s += study.levels[k].own_time_s;
  c.peak_memory_mb = solver_peak_memory_mb * cells_ratio;
  return c;
}

std::optional<PressureDropAnswer> pressure_drop_answer(const Scene& scene, const nlohmann::json& entry,
                                                       const ConvergenceStudy* study) {
  if (!entry.contains("flow")) return std::nullopt;
  const nlohmann::json& flow = entry["flow"];
  PressureDropAnswer a;
  a.section_low_m = entry["section"]["z_low_m"].get<double>();
  a.section_high_m = entry["section"]["z_high_m"].get<double>();
  a.periodic = !entry.value("periodic_mean_velocity_m_s", nlohmann::json()).is_null();
  a.d_ref_m = entry["d_ref_m"].get<double>();
  a.reynolds = entry["parameters"]["reynolds"].get<double>();
  a.finest_pa_m = flow["pressure_gradient_bed_pa_m"].get<double>();
  a.finest_cells = flow["mesh"].value("cells", entry["cells"].get<long>());
  a.finest_converged = flow["converged"].get<bool>();
  if (flow.contains("exact_pa_m")) {
    a.reference_name = "the exact answer of this case";
    a.reference_pa_m = flow["exact_pa_m"].get<double>();
  } else if (flow.contains("bound")) {
    a.reference_name = "Zick & Homsy (1982), the simple cubic array untreated";
    a.reference_bound = cases::KnownBound::from_json(flow["bound"]);
    a.reference_pa_m = a.reference_bound->pa_m;
  } else {
    a.reference_name = "Eisfeld & Schnitzlein (2001)";
    a.reference_pa_m = flow["eisfeld_schnitzlein_bed_pa_m"].get<double>();
    a.reference_accuracy = analysis::kEisfeldSchnitzleinAccuracy;
    a.void_fraction_bed = flow["void_fraction_section_bed"].get<double>();
  }
  if (const nlohmann::json array = entry.value("stokes_array", nlohmann::json()); array.is_object()) {
    a.stokes_array_pa_m = array["van_der_hoef_pa_m"].get<double>();
    a.stokes_array_solid_fraction = array["solid_fraction"].get<double>();
  }
  if (const nlohmann::json why = entry.value("stokes_array_not_compared", nlohmann::json()); why.is_string())
    a.stokes_array_not_compared = why.get<std::string>();
  const double solver_peak_mb = flow.value("solver_peak_memory_mb", 0.0);
  a.residual_u = entry["parameters"].value("residual_u", 0.0);
  a.residual_p = entry["parameters"].value("residual_p", 0.0);
  if (!study) {
    if (const nlohmann::json e = flow.value("pressure_gradient_iteration_error", nlohmann::json()); e.is_object())
      a.iteration_errors.emplace_back(1, analysis::IterationError::from_json(e));
    if (entry["fluid_volume_m3"].is_number())  // gmsh's cells (snappyHexMesh's volume is not known beforehand)
      a.levels.push_back({std::cbrt(entry["fluid_volume_m3"].get<double>() / static_cast<double>(a.finest_cells)), a.finest_pa_m});
    a.why_no_estimate = "the flow was solved on one mesh only, so its discretisation error is not known (on the beds "
                        "measured it was 20-45 %: docs/mesh_case_benchmark.md)";
    const double r3 = std::pow(scene.case_params.convergence.ratio, 3);
    a.advice = fmt::format("set [case.convergence] levels = 3: two coarser meshes, about {} more by this run's time "
                           "(their cells 1 / {:.3g} and 1 / {:.3g} of this one's)",
                           minutes(flow["time_s"].get<double>() * (1.0 / r3 + 1.0 / (r3 * r3))), r3, r3 * r3);
    return a;
  }
  for (const StudyLevel& l : study->levels)
    if (l.failure.empty()) {
      a.levels.push_back({l.cell_size_m, l.pressure_gradient_pa_m});
      if (l.iteration) a.iteration_errors.emplace_back(l.level, *l.iteration);
      if (l.cells_failing_check_mesh > 0) a.failing_check_mesh.emplace_back(l.level, l.cells_failing_check_mesh);
    }
  const bool from_finest = study->complete && study->levels.size() >= 3 && study->levels[0].failure.empty() &&
                           study->levels[1].failure.empty() && study->levels[2].failure.empty();
  const analysis::GridConvergence& g = study->convergence;
  if (!a.finest_converged) {
    a.why_no_estimate = "simpleFoam did not reach its residual targets on the finest mesh (stages.case.flow)";
    a.advice = "raise case.iterations, or see the solver's log in the case";
  } else if (!from_finest) {
    a.why_no_estimate = study->conclusion;
    a.advice = "see the failed levels in report.json (stages.case.convergence.levels); or " +
               finer_study_advice(scene, *study, solver_peak_mb);
  } else if (g.verdict != analysis::GridConvergence::Verdict::monotone || !g.asymptotic) {
    a.why_no_estimate = g.explanation;
    a.advice = finer_study_advice(scene, *study, solver_peak_mb);
  } else {
    a.best_pa_m = g.extrapolated;
    a.gci_fine = g.gci_fine;
    a.order = g.order;
    a.band_low_pa_m = a.finest_pa_m - g.gci_fine * std::abs(a.finest_pa_m);
    a.band_high_pa_m = a.finest_pa_m + g.gci_fine * std::abs(a.finest_pa_m);
    // The same three levels with each one's iteration error taken out, when all three were looked
    // at; a level whose changes did not shrink counts as solved (iteration_lines says how far it moved).
    std::vector<analysis::GridLevel> settled;
    for (int k = 0; k < 3; ++k)
      if (const auto& e = study->levels[k].iteration)
        settled.push_back({study->levels[k].cell_size_m, study->levels[k].pressure_gradient_pa_m * (1.0 + e->remaining)});
    if (settled.size() == 3) a.without_iteration_error = analysis::grid_convergence(settled);
  }
  return a;
}

namespace {

// "+0.24 %" for an estimate, or what was seen instead.
std::string iteration_error_text(const analysis::IterationError& e) {
  return e.geometric ? fmt::format("{:+.2g} %", 100.0 * e.remaining)
                     : fmt::format("not estimated (its changes did not shrink; dp/L moved {:+.2g} % over its last "
                                   "{} iterations)",
                                   100.0 * e.last_change, e.block);
}

}  // namespace

std::vector<std::string> PressureDropAnswer::iteration_lines() const {
  if (iteration_errors.empty()) return {};
  std::vector<std::string> each;
  // A level the band rests on whose dp/L had not settled: its changes did not shrink, and it moved
  // by more than the share of the band's half-width over its last block of iterations alone.
  bool unsettled = false;
  for (const auto& [level, e] : iteration_errors) {
    each.push_back(fmt::format("level {} {}", level, iteration_error_text(e)));
    unsettled = unsettled || (best_pa_m && level <= 3 && !e.geometric &&
                              std::abs(e.last_change) > kIterationErrorShareOfBand * gci_fine);
  }
  std::string line = fmt::format("  iteration error, what each solve's dp/L would still have moved had it run on (by "
                                 "how its last changes shrank; Ferziger & Peric 2002, 5.7): {}",
                                 fmt::join(each, ", "));
  bool moves = false;  // the best estimate, by more than kIterationErrorShareOfBand of the band's half-width
  if (without_iteration_error) {
    const analysis::GridConvergence& w = *without_iteration_error;
    if (w.verdict == analysis::GridConvergence::Verdict::monotone) {
      const double moved = w.extrapolated / *best_pa_m - 1.0;
      moves = std::abs(moved) > kIterationErrorShareOfBand * gci_fine;
      line += fmt::format("; taken out where estimated, the best estimate would be {:.4g} Pa/m ({:+.2g} %) at "
                          "order {:.2f}",
                          w.extrapolated, 100.0 * moved, w.order);
    } else {
      moves = true;
      line += "; taken out where estimated, the three levels would not converge monotonically (" +
              std::string(analysis::verdict_name(w.verdict)) + ")";
    }
  }
  std::vector<std::string> out = {line};
  if (unsettled || moves)
    out.push_back(fmt::format("  that is not small against the band: {} by more than {:g} of the band's half-width "
                              "({:.2g} %); set case.residual_u and case.residual_p below the {:g} and {:g} solved to",
                              unsettled ? "a level it rests on did not settle, and moved over its last block of iterations"
                                        : "it moves the best estimate",
                              kIterationErrorShareOfBand, 100.0 * gci_fine, residual_u, residual_p));
  return out;
}

std::vector<std::string> PressureDropAnswer::lines() const {
  std::vector<std::string> out;
  const std::string where =
      periodic ? fmt::format("dp/L over one period of the periodic section (z = {:.3g} d to {:.3g} d), at Re_p = {:g}",
                             section_low_m / d_ref_m, section_high_m / d_ref_m, reynolds)
               : fmt::format("dp/L over the bed section, {:.3g} d to {:.3g} d above the floor, at Re_p = {:g}",
                             section_low_m / d_ref_m, section_high_m / d_ref_m, reynolds);
  const std::string reference =
      reference_accuracy
          ? fmt::format("  {}: {:.4g} Pa/m +- {:.0f} % (its stated accuracy, docs/reference.md), at the section's void "
                        "fraction of the spheres as packed, {:.4f}",
                        reference_name, reference_pa_m, 100.0 * *reference_accuracy, void_fraction_bed.value_or(0.0))
          : !reference_bound
              ? fmt::format("  {}: {:.6g} Pa/m", reference_name, reference_pa_m)
              : fmt::format("  {}: {:.6g} Pa/m, a bound from {}: the contact treatment {} solid, and Stokes drag at "
                            "a set flow rate only grows with the solid",
                            reference_name, reference_pa_m, reference_bound->side(),
                            reference_bound->from_below ? "adds" : "takes");
  const std::string stokes_array =
      stokes_array_pa_m
          ? fmt::format("  van der Hoef, Beetstra & Kuipers (2005), Stokes drag of random arrays: {:.4g} Pa/m at the "
                        "solid fraction of the spheres as solved, {:.4f} (their fit's accuracy not stated here)",
                        *stokes_array_pa_m, stokes_array_solid_fraction.value_or(0.0))
          : stokes_array_not_compared.empty()
              ? std::string()
              : "  van der Hoef, Beetstra & Kuipers (2005), Stokes drag of random arrays: not compared, " +
                    stokes_array_not_compared;
  if (best_pa_m) {
    out.push_back("answer: " + where);
    out.push_back(fmt::format("  best estimate: {:.4g} Pa/m, the Richardson extrapolation of the three finest meshes "
                              "(apparent order {:.2f}; Celik et al. 2008)",
                              *best_pa_m, order));
    out.push_back(fmt::format("  band: {:.4g} to {:.4g} Pa/m, the finest mesh's {:.4g} Pa/m ({} cells) +- its grid "
                              "convergence index {:.1f} % (Roache's, about 95 % confidence)",
                              *band_low_pa_m, *band_high_pa_m, finest_pa_m, finest_cells, 100.0 * gci_fine));
    for (std::string& l : iteration_lines()) out.push_back(std::move(l));
    out.push_back(reference);
    out.push_back(fmt::format("  best estimate / reference: {:.3f}", *best_pa_m / reference_pa_m));
    if (reference_bound && !reference_bound->reached_by(*band_low_pa_m, *band_high_pa_m))
      out.push_back(fmt::format("  the whole band lies {} the bound, where the mesh-independent value cannot: the "
                                "band is too narrow; refine the study",
                                reference_bound->side()));
    if (stokes_array_pa_m)
      out.push_back(stokes_array + fmt::format("; best estimate / it: {:.3f}", *best_pa_m / *stokes_array_pa_m));
    else if (!stokes_array.empty())
      out.push_back(stokes_array);
  } else {
    out.push_back("answer: " + where + ": no error band, so no best estimate");
    out.push_back(fmt::format("  finest mesh: {:.4g} Pa/m ({} cells), {}", finest_pa_m, finest_cells,
                              finest_converged ? "its discretisation error unknown" : "NOT converged"));
    for (std::string& l : iteration_lines()) out.push_back(std::move(l));
    out.push_back("  why: " + why_no_estimate);
    out.push_back("  to get one: " + advice);
    out.push_back(reference);
    if (!stokes_array.empty()) out.push_back(stokes_array);
  }
  if (reynolds > kUnsteadyFlowReynolds)
    out.push_back(fmt::format("  flow: steady laminar (simpleFoam), but at Re_p = {:g} a packed bed's flow is unsteady "
                              "(from a pore Reynolds number of about {:g}, chaotic past about 300: Dybbs & Edwards "
                              "1984, docs/reference.md); the bed does not settle to this solution, and neither the "
                              "band nor the reference says how far the two differ",
                              reynolds, kUnsteadyFlowReynolds));
  // Said beside the answer, which rests on those meshes (not refused: meshing::check_polyhedra).
  if (!failing_check_mesh.empty()) {
    std::vector<std::string> said;
    for (const auto& [level, cells] : failing_check_mesh) said.push_back(fmt::format("level {}: {}", level, cells));
    out.push_back(fmt::format("  checkMesh: polyhedra fail its limits on the meshes solved ({}; each level's case "
                              "line says where), a defect of the dual not mended yet (docs/findings.md, 2026-11-29)",
                              fmt::join(said, ", ")));
  }
  return out;
}

nlohmann::json PressureDropAnswer::to_json() const {
  nlohmann::json levels_json = nlohmann::json::array();
  for (const analysis::GridLevel& l : levels) levels_json.push_back({{"cell_size_m", l.cell_size}, {"pa_m", l.value}});
  nlohmann::json iteration_json = nlohmann::json::array();
  for (const auto& [level, e] : iteration_errors) iteration_json.push_back({{"level", level}, {"estimate", e.to_json()}});
  nlohmann::json j = {{"quantity", "dp/L over the bed section (Pa/m)"},
                      {"section_z_m", {section_low_m, section_high_m}},
                      {"reynolds", reynolds},
                      {"finest_pa_m", finest_pa_m},
                      {"finest_cells", finest_cells},
                      {"finest_converged", finest_converged},
                      {"levels", levels_json},
                      {"iteration_errors", iteration_json},
                      {"reference",
                       {{"name", reference_name},
                        {"pa_m", reference_pa_m},
                        {"relative_accuracy", reference_accuracy ? nlohmann::json(*reference_accuracy) : nullptr},
                        {"void_fraction_bed", void_fraction_bed ? nlohmann::json(*void_fraction_bed) : nullptr},
                        {"bound", reference_bound ? nlohmann::json(reference_bound->side()) : nlohmann::json()}}},
                      {"lines", lines()}};
  if (stokes_array_pa_m)
    j["stokes_array"] = {{"name", "van der Hoef, Beetstra & Kuipers (2005)"},
                         {"pa_m", *stokes_array_pa_m},
                         {"solid_fraction", *stokes_array_solid_fraction}};
  if (best_pa_m) {
    j["best_estimate_pa_m"] = *best_pa_m;
    j["best_estimate_source"] = "Richardson extrapolation of the three finest levels (Celik et al. 2008)";
    j["band_pa_m"] = {*band_low_pa_m, *band_high_pa_m};
    j["band_source"] = "the finest level's value +- its grid convergence index (Roache 1994, safety factor 1.25)";
    j["gci_fine"] = gci_fine;
    j["apparent_order"] = order;
    j["ratio_to_reference"] = *best_pa_m / reference_pa_m;
    if (without_iteration_error) j["without_iteration_error"] = without_iteration_error->to_json();
  } else {
    j["why_no_estimate"] = why_no_estimate;
    j["advice"] = advice;
  }
  return j;
}

std::string answer_svg(const PressureDropAnswer& a) {
  // Plot area in pixels, and the data ranges: h / d from 0 to past the coarsest level; dp/L
  // over the levels, the band and the reference's accuracy.
  const double left = 80, right = 620, top = 50, bottom = 380;
  double h_max = 0.0, y_low = a.reference_pa_m, y_high = a.reference_pa_m;
  for (const analysis::GridLevel& l : a.levels) {
    h_max = std::max(h_max, l.cell_size / a.d_ref_m);
    y_low = std::min(y_low, l.value), y_high = std::max(y_high, l.value);
  }
  if (a.reference_accuracy)
    y_low = std::min(y_low, a.reference_pa_m * (1.0 - *a.reference_accuracy)),
    y_high = std::max(y_high, a.reference_pa_m * (1.0 + *a.reference_accuracy));
  if (a.best_pa_m)
    y_low = std::min({y_low, *a.band_low_pa_m, *a.best_pa_m}), y_high = std::max({y_high, *a.band_high_pa_m, *a.best_pa_m});
  // Ranges that cannot be empty: no level with a cell size (snappyHexMesh's cells), or one value.
  h_max = h_max > 0.0 ? 1.15 * h_max : 1.0;
  const double pad = y_high > y_low ? 0.05 * (y_high - y_low) : 0.1 * std::max(std::abs(y_high), 1.0);
  y_low -= pad, y_high += pad;
  auto px = [&](double h_d) { return left + (right - left) * h_d / h_max; };
  auto py = [&](double v) { return bottom - (bottom - top) * (v - y_low) / (y_high - y_low); };
  // Ticks at 1, 2 or 5 times a power of ten, about five per axis.
  auto step_of = [](double span) {
    const double raw = span / 5.0, p = std::pow(10.0, std::floor(std::log10(raw))), m = raw / p;
    return p * (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0);
  };
  std::string s = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"700\" height=\"460\" font-family=\"sans-serif\" "
      "font-size=\"13\">\n<rect width=\"700\" height=\"460\" fill=\"white\"/>\n"
      "<text x=\"{}\" y=\"28\" font-size=\"15\">Bed pressure gradient against cell size (Re_p = {:g})</text>\n",
      left, a.reynolds);
  // The reference and its stated accuracy.
  if (a.reference_accuracy)
    s += fmt::format("<rect x=\"{}\" y=\"{:.1f}\" width=\"{}\" height=\"{:.1f}\" fill=\"#dfe8f5\"/>\n", left,
                     py(a.reference_pa_m * (1.0 + *a.reference_accuracy)), right - left,
                     py(a.reference_pa_m * (1.0 - *a.reference_accuracy)) - py(a.reference_pa_m * (1.0 + *a.reference_accuracy)));
  s += fmt::format("<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#3060a0\" stroke-dasharray=\"6 4\"/>\n",
                   left, right, py(a.reference_pa_m), py(a.reference_pa_m));
  // Axes, ticks and labels.
  s += fmt::format("<path d=\"M{0} {1} V{2} H{3}\" fill=\"none\" stroke=\"black\"/>\n", left, top, bottom, right);
  const double hx = step_of(h_max), vy = step_of(y_high - y_low);
  for (double h = 0.0; h <= h_max + 1e-12; h += hx)
    s += fmt::format("<line x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1}\" y2=\"{2}\" stroke=\"black\"/><text x=\"{0:.1f}\" "
                     "y=\"{3}\" text-anchor=\"middle\">{4:g}</text>\n",
                     px(h), bottom, bottom + 5, bottom + 20, std::round(h / hx) * hx);
  for (double v = std::ceil(y_low / vy) * vy; v <= y_high; v += vy)
    s += fmt::format("<line x1=\"{0}\" x2=\"{1}\" y1=\"{2:.1f}\" y2=\"{2:.1f}\" stroke=\"black\"/><text x=\"{3}\" "
                     "y=\"{4:.1f}\" text-anchor=\"end\">{5:g}</text>\n",
                     left - 5, left, py(v), left - 8, py(v) + 4, std::round(v / vy) * vy);
  s += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">cell size h / d</text>\n", (left + right) / 2, bottom + 42);
  s += fmt::format("<text transform=\"translate(22 {}) rotate(-90)\" text-anchor=\"middle\">dp/L (Pa/m)</text>\n",
                   (top + bottom) / 2);
  // The power law of the finest three through the best estimate, and the band at the finest level.
  if (a.best_pa_m && !a.levels.empty()) {
    const double h1 = a.levels.front().cell_size / a.d_ref_m, h_end = a.levels.size() >= 3 ? a.levels[2].cell_size / a.d_ref_m : h1;
    std::string points;
    for (int k = 0; k <= 60; ++k) {
      const double h = h_end * k / 60.0;
      points += fmt::format("{:.1f},{:.1f} ", px(h), py(*a.best_pa_m + (a.finest_pa_m - *a.best_pa_m) * std::pow(h / h1, a.order)));
    }
    s += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"#c04020\"/>\n", points);
    s += fmt::format("<path d=\"M{0:.1f} {1:.1f} V{2:.1f} M{3:.1f} {1:.1f} H{4:.1f} M{3:.1f} {2:.1f} H{4:.1f}\" "
                     "stroke=\"#c04020\" stroke-width=\"2\"/>\n",
                     px(h1), py(*a.band_low_pa_m), py(*a.band_high_pa_m), px(h1) - 6, px(h1) + 6);
    s += fmt::format("<path d=\"M{0:.1f} {1:.1f} l7 7 l-7 7 l-7 -7 z\" fill=\"#c04020\"/>\n", px(0.0), py(*a.best_pa_m) - 7);
  }
  for (const analysis::GridLevel& l : a.levels)
    s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"5\" fill=\"black\"/>\n", px(l.cell_size / a.d_ref_m), py(l.value));
  // Legend, on white over the reference's band.
  s += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"280\" height=\"80\" fill=\"white\" fill-opacity=\"0.85\"/>\n",
                   right - 280, top - 4);
  double y = top + 8;
  auto legend = [&](const std::string& mark, const std::string& text) {
    s += mark + fmt::format("<text x=\"{}\" y=\"{:.1f}\">{}</text>\n", right - 250, y + 4, escaped(text));
    y += 18;
  };
  legend(fmt::format("<circle cx=\"{}\" cy=\"{:.1f}\" r=\"5\" fill=\"black\"/>", right - 265, y), "the study's levels");
  if (a.best_pa_m) {
    legend(fmt::format("<path d=\"M{} {:.1f} l7 7 l-7 7 l-7 -7 z\" fill=\"#c04020\"/>", right - 265, y - 7),
           fmt::format("best estimate {:.4g} Pa/m (Richardson)", *a.best_pa_m));
    legend(fmt::format("<line x1=\"{0}\" x2=\"{0}\" y1=\"{1:.1f}\" y2=\"{2:.1f}\" stroke=\"#c04020\" stroke-width=\"2\"/>",
                       right - 265, y - 7, y + 7),
           fmt::format("band {:.4g} to {:.4g} Pa/m (GCI {:.1f} %)", *a.band_low_pa_m, *a.band_high_pa_m, 100.0 * a.gci_fine));
  } else {
    // The reason in full is in summary.txt; the legend has room for its gist only.
    legend("", "no best estimate: " + std::string(!a.finest_converged ? "the finest solve did not converge"
                                                  : a.levels.size() < 3 ? "too few levels"
                                                                        : "the study gives none (summary.txt)"));
  }
  legend(fmt::format("<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#3060a0\" stroke-dasharray=\"6 4\"/>",
                     right - 275, right - 255, y, y),
         a.reference_accuracy ? fmt::format("{} +- {:.0f} %", a.reference_name, 100.0 * *a.reference_accuracy)
                              : a.reference_name);
  return s + "</svg>\n";
}

}  // namespace bedforge::pipeline
