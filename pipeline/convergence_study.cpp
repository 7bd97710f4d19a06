#include "pipeline/convergence_study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>

#include "core/atomic_file.hpp"
#include "core/bed_io.hpp"
#include "core/stage_meter.hpp"
#include "core/version.hpp"
#include "pipeline/case_stage.hpp"
#include "pipeline/mesh_stage.hpp"
#include "pipeline/piece_stage.hpp"
#include "pipeline/surface_stage.hpp"

namespace bedforge::pipeline {

namespace fs = std::filesystem;

nlohmann::json ConvergenceStudy::to_json() const {
  nlohmann::json out = {{"complete", complete}, {"conclusion", conclusion}, {"levels", nlohmann::json::array()}};
  for (const StudyLevel& l : levels) {
    nlohmann::json j = {{"level", l.level}, {"scale", l.scale}, {"time_s", l.time_s}, {"alpha", l.alpha},
                        {"cache_key", l.cache_key}};
    if (l.reused) j["reused"] = true;
    if (!l.sizing.empty()) {
      j["sizing"] = nlohmann::json::array();
      for (const auto& [scale, h] : l.sizing) j["sizing"].push_back({{"scale", scale}, {"predicted_cell_size_m", h}});
    }
    if (l.failure.empty()) {
      j.update({{"cells", l.cells},
                {"cell_size_m", l.cell_size_m},
                {"pressure_gradient_bed_pa_m", l.pressure_gradient_pa_m},
                {"converged", l.converged},
                {"iteration_error", l.iteration ? l.iteration->to_json() : nlohmann::json()},
                {"stopped_by", l.stopped_by},
                {"cells_failing_check_mesh", l.cells_failing_check_mesh},
                {"own_time_s", l.own_time_s},
                {"drag", l.drag.to_json()}});
      if (exact_pa_m) j["relative_error_to_exact"] = l.pressure_gradient_pa_m / *exact_pa_m - 1.0;
    } else {
      j["failure"] = l.failure;
    }
    out["levels"].push_back(std::move(j));
  }
  if (complete) out["grid_convergence"] = convergence.to_json();
  if (fit) out["least_squares"] = fit->to_json();
  if (exact_pa_m) {
    out["exact_pa_m"] = *exact_pa_m;
    out["order_from_exact"] = std::isfinite(order_from_exact) ? nlohmann::json(order_from_exact) : nullptr;
    if (complete && std::isfinite(convergence.extrapolated))
      out["extrapolated_error_to_exact"] = convergence.extrapolated / *exact_pa_m - 1.0;
  }
  if (bound) {
    out["bound"] = bound->to_json();
    if (complete && std::isfinite(convergence.extrapolated))
      out["extrapolated_ratio_to_bound"] = convergence.extrapolated / bound->pa_m;
  }
  return out;
}

StudyLevel study_level_from_json(const nlohmann::json& j, std::optional<double> exact_pa_m) {
  StudyLevel l;
  l.level = j.at("level").get<int>();
  l.scale = j.at("scale").get<double>();
  l.time_s = j.at("time_s").get<double>();
  l.alpha = j.value("alpha", 1.0);
  l.cache_key = j.value("cache_key", "");
  for (const auto& s : j.value("sizing", nlohmann::json::array()))
    l.sizing.emplace_back(s.at("scale").get<double>(), s.at("predicted_cell_size_m").get<double>());
  if (j.contains("failure")) {
    l.failure = j["failure"].get<std::string>();
    return l;
  }
  l.cells = j.at("cells").get<long>();
  l.cell_size_m = j.at("cell_size_m").get<double>();
  l.pressure_gradient_pa_m = j.at("pressure_gradient_bed_pa_m").get<double>();
  l.converged = j.at("converged").get<bool>();
  if (const nlohmann::json e = j.value("iteration_error", nlohmann::json()); e.is_object())
    l.iteration = analysis::IterationError::from_json(e);
  l.stopped_by = j.value("stopped_by", "");  // reports before 2026-12-07 (session 96) lack it
  l.cells_failing_check_mesh = j.value("cells_failing_check_mesh", 0L);  // reports before 2026-11-29 lack it
  l.own_time_s = j.at("own_time_s").get<double>();
  l.drag = cases::Drag::from_json(j.at("drag"));
  l.exact_pa_m = exact_pa_m;
  return l;
}

namespace {
// The first guess of the exponent in cell size ~ lengths^alpha: a calibration on the a = 5,
// N = 500 studies, whose level 2 measured 0.80-0.91 over four treatments and Reynolds numbers
// (docs/findings.md, session 35). With 1, the cells grow less than the lengths, so level 2 came
// out 4-5 % small and was meshed twice in every one of them.
constexpr double kFirstSizingExponent = 0.85;
}  // namespace

LevelLengths level_lengths(const Scene& scene, double scale) {
  LevelLengths l{scene.surface, scene.mesh};
  l.surface.edge_length_d *= scale;
  l.surface.contact_edge_length_d *= scale;
  l.surface.cells_per_gap /= scale;
  l.mesh.max_size_d *= scale;
  l.mesh.layers.thickness_d *= scale;  // the layers' count and growth stay: each layer scales
  l.mesh.layers.room_scale /= scale;    // their room rule applied at the same lengths on every level
  return l;
}

meshing::PrismLayerParams layers_for_study(meshing::PrismLayerParams layers, const cases::CaseParams::Convergence& study) {
  if (layers.count > 0 && study.levels > 0)
    layers.room_scale = std::pow(study.ratio, (study.levels - 1) / kFirstSizingExponent);
  return layers;
}

StudyLevel study_level(const CaseStage& solved, int level, double scale, double surface_mesh_s) {
  StudyLevel l;
  l.level = level;
  l.scale = scale;
  l.cells = solved.flow->solved_cells >= 0 ? solved.flow->solved_cells : solved.info.cells;  // the cells solved on
  l.cell_size_m = std::cbrt(solved.info.fluid_volume_m3.value() / static_cast<double>(l.cells));  // gmsh cells: known
  l.pressure_gradient_pa_m = solved.flow->pressure_gradient_bed_pa_m;
  l.converged = solved.flow->converged;
  l.iteration = solved.flow->pressure_gradient_iteration;
  l.stopped_by = solved.flow->stopped_by;
  if (solved.info.polyhedra_quality) l.cells_failing_check_mesh = solved.info.polyhedra_quality->failing_cells;
  l.drag = solved.flow->drag;
  l.exact_pa_m = solved.flow->exact_pa_m;
  l.bound = solved.flow->bound;
  if (!l.converged) l.failure = "simpleFoam did not converge to the residual targets";
  l.time_s = solved.report["time_s"].get<double>();
  l.own_time_s = surface_mesh_s + l.time_s;
  return l;
}

namespace {

// A level's cells must reach their target size within this fraction, tried at most this often.
constexpr double kSizeTolerance = 0.03;
constexpr int kSizingAttempts = 4;

// The cells the flow will be solved on, from the tetrahedra before the case is written:
// the dual has one polyhedron per point.
long cells_to_solve(const meshing::PolyMesh& tets, bool polyhedra) {
  return polyhedra ? static_cast<long>(tets.points.size()) : tets.cells;
}

// A mesh scale and the size of the cells it made (m).
struct Sized {
  double scale, h;
};

// Where level k's case is: `level_dir` itself; or in a study in pieces level_dir/case, beside
// the bed.csv and scene.toml (the scene with the level's lengths) that the level's ranks read.
fs::path level_case_dir(const fs::path& level_dir, bool in_pieces) { return in_pieces ? level_dir / "case" : level_dir; }
// A file that a solved level's case holds: its cells, or in pieces the first piece's.
fs::path level_mesh_file(const fs::path& level_dir, bool in_pieces) {
  return level_case_dir(level_dir, in_pieces) / (in_pieces ? "processor0/constant/polyMesh/owner" : "constant/polyMesh/owner");
}

// Level k's case written in pieces by ranks of their own (piece_stage.hpp), not run: its bed and
// its scene with the level's lengths into `level_dir` for the ranks, then the case.
CaseStage write_level_in_pieces(const Scene& scene, const Bed& bed, const LevelLengths& lengths,
                                const fs::path& level_dir, const Console& console) {
  const Provenance prov{kVersion, scene.seed, scene.to_json()};
  toml::table table = scene.table;
  apply_overrides(table, {{"surface.edge_length_d", lengths.surface.edge_length_d},
                          {"surface.contact_edge_length_d", lengths.surface.contact_edge_length_d},
                          {"surface.cells_per_gap", lengths.surface.cells_per_gap},
                          {"mesh.max_size_d", lengths.mesh.max_size_d}});
  const std::string toml_text = scene_to_toml(table);
  fs::create_directories(level_dir);
  write_file_atomically(level_dir / "bed.csv", bed_to_csv(bed, prov));
  write_file_atomically(level_dir / "scene.toml", toml_text);
  cases::CaseParams params = scene.case_params;
  params.run = false;  // sized first, solved once
  const CasePieces pieces = case_pieces(bed, lengths.surface, scene.mesh.pieces, level_dir, console);
  return case_stage(nullptr, nullptr, bed, params, prov, toml_text, {}, level_dir / "case", true,
                    treated_solid(scene.surface, bed), console, &pieces);
}

// Level k of the study, solved in `case_dir`, its cells of size `target_h_m`. The mesh lengths
// do not set the cell size in proportion (points per sphere and per contact loop and the wall
// rules stay), so the scale is searched in log-log secant steps, starting from `finer`
// (the finer level's scale and size; the next level's on return) and an exponent `alpha` of
// h ~ scale^alpha, updated with what was measured.
StudyLevel solve_level(const Scene& scene, const Bed& bed, int k, double target_h_m, Sized& finer, double& alpha,
                       const fs::path& case_dir, const Console& console) {
  const StageMeter meter;
  StudyLevel l;
  l.level = k;
  double scale = finer.scale * std::pow(target_h_m / finer.h, 1.0 / alpha);
  const bool in_pieces = scene.mesh.pieces > 1;
  try {
    std::optional<MeshStage> m;
    std::optional<CaseStage> written;  // in pieces: the case the last attempt's ranks wrote
    double surface_mesh_s = 0.0;  // of the last attempt, the mesh solved on
    double last_scale = finer.scale, last_h = finer.h;
    for (int attempt = 1;; ++attempt) {
      const LevelLengths lengths = level_lengths(scene, scale);
      double h = 0.0;
      if (in_pieces) {
        written = write_level_in_pieces(scene, bed, lengths, case_dir, console);
        surface_mesh_s = written->report["time_s"].get<double>();
        h = std::cbrt(written->info.fluid_volume_m3.value() / static_cast<double>(written->info.cells));
      } else {
        const SurfaceStage s = surface_stage(bed, lengths.surface, case_dir.parent_path() / "bad_triangles.vtp", console);
        m.reset();  // the previous attempt's mesh is not needed any more
        m = mesh_stage(s.surface->fluid, s.surface->exact_volume_m3, bed, lengths.surface, lengths.mesh, {},
                       case_dir.parent_path() / "bad_cells.vtk", console);
        surface_mesh_s = s.report["time_s"].get<double>() + m->report["time_s"].get<double>();
        h = std::cbrt(m->volume->quality.total_volume /
                      static_cast<double>(cells_to_solve(m->volume->mesh, scene.case_params.polyhedra)));
      }
      l.sizing.push_back({scale, h});
      const double off = h / target_h_m - 1.0;
      console.line(fmt::format("convergence: level {}, mesh lengths x {:.3g}: cells of {:.4g} d, {:+.1f} % off the "
                               "target", k, scale, h / reference_diameter(bed), 100.0 * off));
      if (std::abs(std::log(scale / last_scale)) > 1e-3)
        alpha = std::clamp(std::log(h / last_h) / std::log(scale / last_scale), 0.2, 2.0);
      if (std::abs(off) <= kSizeTolerance || attempt == kSizingAttempts) {
        finer = {scale, h};
        break;
      }
      last_scale = scale, last_h = h;
      scale *= std::pow(target_h_m / h, 1.0 / alpha);
    }
    std::optional<CaseStage> c;
    if (in_pieces) {
      c = std::move(written);
      solve_case_stage(*c, console);
    } else {
      const Provenance prov{kVersion, scene.seed, scene.to_json()};
      cases::CaseParams params = scene.case_params;
      params.snappy = false;  // a coarser level is solved on its gmsh cells only
      const meshing::PolyMesh* cells = &m->volume->mesh;
      c = case_stage({std::move(m->volume), cells}, nullptr, bed, params, prov, scene_to_toml(scene.table), {}, case_dir,
                     true, treated_solid(scene.surface, bed), console);
    }
    StudyLevel solved = study_level(*c, k, scale, surface_mesh_s);
    solved.sizing = std::move(l.sizing);
    l = std::move(solved);
  } catch (const std::exception& e) {
    l.scale = scale;
    l.failure = e.what();
  }
  l.time_s = meter.seconds();
  return l;
}

}  // namespace

ConvergenceStudy convergence_study(const Scene& scene, const Bed& bed, const StudyLevel& finest, const fs::path& dir,
                                   const Console& console, const nlohmann::json& earlier) {
  const cases::CaseParams::Convergence& p = scene.case_params.convergence;
  ConvergenceStudy study;
  study.levels.push_back(finest);
  // Levels an earlier run left beyond this study's are not part of it.
  if (fs::exists(dir))
    for (const auto& e : fs::directory_iterator(dir)) {
      int k = 0;
      if (std::sscanf(e.path().filename().c_str(), "level_%d", &k) == 1 && k > p.levels) fs::remove_all(e.path());
    }
  // Each level's cells `ratio` times the size of the finer one's, measured on the cells solved
  // on (Celik et al. 2008 ask r >= 1.3 of the grids, not of the settings that make them).
  Sized finer{1.0, finest.cell_size_m};
  double alpha = kFirstSizingExponent;
  const bool in_pieces = scene.mesh.pieces > 1;
  for (int k = 2; k <= p.levels; ++k) {
    const double target = finest.cell_size_m * std::pow(p.ratio, k - 1);
    const fs::path level_dir = dir / fmt::format("level_{}", k);
    // A level follows from its finer one's (its sizing starts there), the ratio and its number.
    const std::string key =
        stage_key({{"finer", study.levels.back().cache_key}, {"ratio", p.ratio}, {"level", k}});
    nlohmann::json before;
    if (earlier.is_object())
      for (const auto& l : earlier.value("levels", nlohmann::json::array()))
        if (l.value("level", 0) == k && l.value("cache_key", "") == key) before = l;
    if (before.is_object() && !before.contains("failure") && fs::exists(level_mesh_file(level_dir, in_pieces))) {
      StudyLevel l = study_level_from_json(before, finest.exact_pa_m);
      l.reused = true;
      finer = {l.sizing.back().first, l.sizing.back().second};
      alpha = l.alpha;
      console.line(fmt::format("convergence: level {} of {} reused from {} ({} cells, dp/L {:.5g} Pa/m)", k, p.levels,
                               level_case_dir(level_dir, in_pieces).string(), l.cells,
                               l.pressure_gradient_pa_m));
      study.levels.push_back(std::move(l));
      continue;
    }
    console.line(fmt::format("convergence: level {} of {}, cells of {:.4g} d wanted", k, p.levels,
                             target / reference_diameter(bed)));
    StudyLevel l = solve_level(scene, bed, k, target, finer, alpha, level_dir, console);
    l.alpha = alpha;
    l.cache_key = key;
    study.levels.push_back(std::move(l));
  }
  // The finest three levels in a row that gave a value.
  for (std::size_t first = 0; first + 2 < study.levels.size(); ++first) {
    const StudyLevel* three[] = {&study.levels[first], &study.levels[first + 1], &study.levels[first + 2]};
    if (!three[0]->failure.empty() || !three[1]->failure.empty() || !three[2]->failure.empty()) continue;
    study.convergence = analysis::grid_convergence({{three[0]->cell_size_m, three[0]->pressure_gradient_pa_m},
                                                    {three[1]->cell_size_m, three[1]->pressure_gradient_pa_m},
                                                    {three[2]->cell_size_m, three[2]->pressure_gradient_pa_m}});
    study.complete = true;
    study.conclusion = fmt::format("levels {}-{}: {}", three[0]->level, three[2]->level, study.convergence.explanation);
    if (first > 0) study.conclusion += " (a finer level failed, so the finest here is not the scene's own mesh)";
    break;
  }
  if (!study.complete) {
    std::string failed;
    for (const StudyLevel& l : study.levels)
      if (!l.failure.empty()) failed += fmt::format("{}level {}: {}", failed.empty() ? "" : "; ", l.level, l.failure);
    study.conclusion = "no three successive levels gave a pressure drop, so no error estimate: " + failed;
  }
  std::vector<analysis::GridLevel> solved;
  for (const StudyLevel& l : study.levels)
    if (l.failure.empty()) solved.push_back({l.cell_size_m, l.pressure_gradient_pa_m});
  const bool coarser_each = std::adjacent_find(solved.begin(), solved.end(), [](const auto& a, const auto& b) {
                              return b.cell_size <= a.cell_size;
                            }) == solved.end();
  if (solved.size() >= 4 && coarser_each) {
    study.fit = analysis::fit_power_law(solved);
    study.conclusion += "; " + study.fit->explanation;
  }
  if (finest.exact_pa_m) {
    const double exact = *finest.exact_pa_m;
    study.exact_pa_m = exact;
    study.order_from_exact = analysis::observed_order(solved, exact);
    study.conclusion += fmt::format("; against the exact {:.5g} Pa/m", exact);
    if (!solved.empty())
      study.conclusion +=
          fmt::format(": finest solved level {:+.3f} %, ", 100.0 * (solved.front().value / exact - 1.0)) +
          (std::isfinite(study.order_from_exact)
               ? fmt::format("order {:.2f} from the exact errors", study.order_from_exact)
               : std::string("no order from the exact errors (fewer than two, or on both sides of the exact value)"));
    if (study.complete && std::isfinite(study.convergence.extrapolated))
      study.conclusion += fmt::format(", extrapolated {:+.3f} %",
                                      100.0 * (study.convergence.extrapolated / exact - 1.0));
  }
  if (finest.bound && !solved.empty()) {
    const cases::KnownBound& b = *finest.bound;
    study.bound = b;
    study.conclusion += fmt::format("; against the untreated array's {:.5g} Pa/m, a bound from {} (the treatment {} "
                                    "solid): finest solved level {:+.3f} %",
                                    b.pa_m, b.side(), b.from_below ? "adds" : "takes",
                                    100.0 * (solved.front().value / b.pa_m - 1.0));
    if (study.complete && std::isfinite(study.convergence.extrapolated)) {
      const double x = study.convergence.extrapolated, f = solved.front().value;
      const double half = study.convergence.gci_fine * std::abs(f);  // the band: the finest +- its GCI
      const bool band_reaches = b.reached_by(f - half, f + half);
      study.conclusion += fmt::format(", extrapolated {:+.3f} %", 100.0 * (x / b.pa_m - 1.0));
      if (!b.holds(x))
        study.conclusion += band_reaches ? ", past the bound but within its band"
                                         : ", past the bound with its whole band, where the mesh-independent value "
                                           "cannot lie: the band is too narrow";
    }
  }
  return study;
}

StudyLevel finest_level(const CaseStage& solved, const Report& report, const std::string& case_key) {
  // A mesh made outside this report (bedforge case on a copied fluid.msh) counts as free.
  const nlohmann::json none = nlohmann::json::object(), stages = report.data().value("stages", none);
  const double surface_mesh_s =
      stages.value("surface", none).value("time_s", 0.0) + stages.value("mesh", none).value("time_s", 0.0);
  StudyLevel finest = study_level(solved, 1, 1.0, surface_mesh_s);
  finest.cache_key = case_key;
  return finest;
}

void remove_convergence_study(nlohmann::json& case_entry) {
  if (!case_entry.contains("convergence")) return;
  const std::string summary = case_entry.value("summary", ""),
                    study = "; convergence: " + case_entry["convergence"].value("conclusion", "");
  if (summary.size() >= study.size() && summary.compare(summary.size() - study.size(), study.size(), study) == 0)
    case_entry["summary"] = summary.substr(0, summary.size() - study.size());
  case_entry.erase("convergence");
}

ConvergenceStudy add_convergence_study(const Scene& scene, const Bed& bed, const StudyLevel& finest, const nlohmann::json& earlier,
                           const fs::path& dir, const Console& console, nlohmann::json& case_entry) {
  const ConvergenceStudy study = convergence_study(scene, bed, finest, dir / "convergence", console, earlier);
  remove_convergence_study(case_entry);
  case_entry["convergence"] = study.to_json();
  const std::string line = "convergence: " + study.conclusion;
  case_entry["summary"] = case_entry["summary"].get<std::string>() + "; " + line;
  console.line(line);
  return study;
}

}  // namespace bedforge::pipeline
