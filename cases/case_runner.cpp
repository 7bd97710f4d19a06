#include "cases/case_runner.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <future>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include "analysis/pressure_drop.hpp"
#include "core/error.hpp"
#include "core/report.hpp"
#include "core/stage_meter.hpp"

namespace bedforge::cases {

namespace fs = std::filesystem;

nlohmann::json FlowResult::to_json() const {
  nlohmann::json mesh = {{"mesher", mesher}};
  if (solved_cells >= 0) mesh["cells"] = solved_cells;
  if (solved_volume_m3) mesh["volume_m3"] = *solved_volume_m3;
  if (volume_lost) mesh["volume_lost"] = *volume_lost;
  nlohmann::json allrun = nlohmann::json::array();
  for (const Step& s : steps) allrun.push_back({{"step", s.name}, {"time_s", s.time_s}, {"peak_memory_mb", s.peak_memory_mb}});
  nlohmann::json j = {{"time_s", time_s},
          {"solver_peak_memory_mb", solver_peak_memory_mb},
          {"allrun_steps", allrun},
          {"mesh", mesh},
          {"iterations", iterations},
          {"history", history},
          {"converged", converged},
          {"stopped_by", stopped_by},
          {"final_initial_residual", {{"U", residual_u}, {"p", residual_p}}},
          {"pressure_gradient_bed_pa_m", pressure_gradient_bed_pa_m},
          {"pressure_gradient_change_last_block",
           pressure_gradient_iteration ? std::abs(pressure_gradient_iteration->last_change) : 0.0},
          {"pressure_gradient_iteration_error",
           pressure_gradient_iteration ? pressure_gradient_iteration->to_json() : nlohmann::json()},
          {"pressure_drop_inlet_outlet_pa", pressure_drop_inlet_outlet_pa},
          {"flow_rate_m3_s", flow_rate_m3_s},
          {"flow_rate_relative_error", flow_rate_relative_error},
          {"drag", drag.to_json()}};
  if (van_der_hoef_pa_m) {
    j["van_der_hoef_pa_m"] = *van_der_hoef_pa_m;
    j["ratio_to_van_der_hoef"] = *ratio_to_van_der_hoef;
  }
  if (bound) {
    j["bound"] = bound->to_json();
    j["ratio_to_bound"] = ratio_to_bound;
  }
  if (exact_pa_m) {
    j["exact_pa_m"] = *exact_pa_m;
    j["relative_error_to_exact"] = relative_error_to_exact;
  } else {
    auto known = [](const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(); };
    j["eisfeld_schnitzlein_pa_m"] = known(eisfeld_schnitzlein_pa_m);
    j["ratio_to_eisfeld_schnitzlein"] = known(ratio_to_eisfeld_schnitzlein);
    j["void_fraction_section"] = known(void_fraction_section);
    j["eisfeld_schnitzlein_bed_pa_m"] = eisfeld_schnitzlein_bed_pa_m;
    j["ratio_to_eisfeld_schnitzlein_bed"] = ratio_to_eisfeld_schnitzlein_bed;
    j["void_fraction_section_bed"] = void_fraction_section_bed;
    j["drag"]["wall_share_eisfeld_schnitzlein"] = wall_share_of_drag_eisfeld_schnitzlein;
  }
  return j;
}

namespace {

// The data rows of a function object's output file `file` (comment lines left out), its
// vectors' parentheses turned into spaces so that every number reads as a column.
std::vector<std::string> output_rows(const fs::path& case_dir, const std::string& name, const std::string& file) {
  const fs::path path = case_dir / "postProcessing" / name / "0" / file;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("the solver wrote no " + path.string());
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), '(', ' ');
    std::replace(line.begin(), line.end(), ')', ' ');
    rows.push_back(std::move(line));
  }
  if (rows.empty()) throw std::runtime_error("no value in " + path.string());
  return rows;
}

// The values (second column) of a surfaceFieldValue object's output, one per iteration.
std::vector<double> series(const fs::path& case_dir, const std::string& name) {
  std::vector<double> v;
  for (const std::string& line : output_rows(case_dir, name, "surfaceFieldValue.dat")) {
    std::istringstream row(line);
    double t = 0.0, x = 0.0;
    if (row >> t >> x) v.push_back(x);
  }
  if (v.empty()) throw std::runtime_error(fmt::format("no value in {}'s output", name));
  return v;
}

// The last force along z (N) in a forces object's output, in all and its viscous part.
struct ForceZ {
  double total = 0.0, viscous = 0.0;
};
ForceZ last_force_z(const fs::path& case_dir, const std::string& name) {
  std::istringstream row(output_rows(case_dir, name, "force.dat").back());  // time, total, pressure, viscous
  double t = 0.0, total[3], pressure[3], viscous[3];
  if (!(row >> t >> total[0] >> total[1] >> total[2] >> pressure[0] >> pressure[1] >> pressure[2] >> viscous[0] >>
        viscous[1] >> viscous[2]))
    throw std::runtime_error(fmt::format("no force in {}'s output", name));
  return {total[2], viscous[2]};
}

// What the log `path`, being written, gained since its first `read` bytes, up to its last
// "Time = " line (the iterations before it are finished); `read` moves past it. Empty while no
// iteration has finished since, or while there is no log.
std::string finished_since(const fs::path& path, std::streamoff& read) {
  std::ifstream log(path, std::ios::binary);
  if (!log.seekg(read)) return {};
  const std::string added{std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>()};
  const std::size_t next = added.rfind("\nTime = ");
  if (next == std::string::npos) return {};
  read += static_cast<std::streamoff>(next + 1);
  return added.substr(0, next + 1);
}

// One SIMPLE iteration of a simpleFoam log: its `Time = N`, the initial residuals (the largest
// of U's components, p's first solve), the ExecutionTime at its end and, in a periodic section,
// the kinematic pressure gradient meanVelocityForce applied (its last line of the iteration).
struct Iteration {
  long step = 0;
  double res_u = 0.0, res_p = 0.0, time_s = 0.0;
  bool p_seen = false;
  double driving_gradient = 0.0;
};

// The iterations of a solver log, in order; `converged` is set when SIMPLE says so. Text before
// the first `Time =` (or a log's tail cut mid-iteration) starts no iteration.
std::vector<Iteration> read_iterations(std::istream& log, bool* converged = nullptr) {
  std::vector<Iteration> its;
  std::string line;
  while (std::getline(log, line)) {
    if (line.rfind("Time = ", 0) == 0) its.push_back({std::atol(line.c_str() + 7)});
    if (converged && line.find("SIMPLE solution converged") != std::string::npos) *converged = true;
    if (its.empty()) continue;
    Iteration& it = its.back();
    if (line.rfind("ExecutionTime = ", 0) == 0) it.time_s = std::atof(line.c_str() + 16);
    if (const auto g = line.find("pressure gradient = "); g != std::string::npos)
      it.driving_gradient = std::atof(line.c_str() + g + 20);
    const auto at = line.find("Initial residual = ");
    if (at == std::string::npos) continue;
    const double r = std::atof(line.c_str() + at + 19);
    if (line.find("Solving for U") != std::string::npos) it.res_u = std::max(it.res_u, r);
    if (line.find("Solving for p,") != std::string::npos && !it.p_seen) it.res_p = r, it.p_seen = true;
  }
  return its;
}

// Controls a running solve through its controlDict (OpenFOAM reads it again when it changes, the
// case being written with runTimeModifiable): stopAt writeNow ends the run after the current
// iteration with its fields written; endTime is the case's own. Written beside and renamed, so
// that the solver never reads half a file. OpenFOAM takes a file as changed only when its time
// stamp is past the one it read by more than fileModificationSkew (10 s in Debian's
// etc/controlDict): a small case stopped within 10 s of being written ran on to its end, so the
// new file is stamped at least twice that after the old one.
void set_stop_at(const fs::path& case_dir, const std::string& when) {
  const fs::path dict = case_dir / "system" / "controlDict", written = case_dir / "system" / "controlDict.stopping";
  const fs::file_time_type was = fs::last_write_time(dict);
  std::ifstream in(dict);
  std::ofstream out(written);
  for (std::string line; std::getline(in, line);)
    out << (line.rfind("stopAt", 0) == 0 ? fmt::format("stopAt          {};", when) : line) << '\n';
  out.close();
  fs::last_write_time(written, std::max(fs::last_write_time(written), was + std::chrono::seconds(20)));
  fs::rename(written, dict);
}

// The last finished iteration of a log being written (step 0 before there is one). Only the
// log's tail is read, so polling a long run stays cheap.
Iteration last_iteration(const fs::path& log_path) {
  std::ifstream log(log_path, std::ios::binary | std::ios::ate);
  if (!log) return {};
  const std::streamoff size = log.tellg(), tail = std::min<std::streamoff>(size, 1 << 16);
  std::string text(static_cast<std::size_t>(tail), '\0');
  log.seekg(size - tail);
  log.read(text.data(), tail);
  std::istringstream in(text);
  const std::vector<Iteration> its = read_iterations(in);
  for (auto it = its.rbegin(); it != its.rend(); ++it)
    if (it->time_s > 0.0) return *it;  // ExecutionTime closes an iteration
  return {};
}

// The bed's pressure gradient (Pa/m) at each iteration of `its`: between the section planes, or
// in a periodic section the one that drove the flow, at the superficial velocity set.
// meanVelocityForce holds the cells' volume-mean velocity, whose flow rate differs from the one
// set by a discretisation error (-8 % at 250 polyhedra per sphere, -2.6 % at 2.6 k, falling with
// the cells); the gradient is scaled by the flow rate set over the one solved, as Darcy's law has
// it (at Re_p = 1 inertia is a few % of the drag, so the scaling errs by a few % of that error).
// `running`: the monitors are still being written, so their last row, perhaps cut, is left out.
std::vector<double> bed_gradients(const CaseInfo& c, const std::vector<Iteration>& its, bool running) {
  const double rho = c.params.density_kg_m3;
  std::vector<double> g;
  if (c.mean_velocity_m_s) {
    const std::vector<double> flows = series(c.directory, "flowRate");
    const std::size_t n = std::max<std::size_t>(std::min(its.size(), flows.size()), 1) - (running ? 1 : 0);
    for (std::size_t k = 0; k < n; ++k)
      g.push_back(rho * its[k].driving_gradient * c.velocity_m_s * c.inlet_area_m2 / flows[k]);
    return g;
  }
  const std::vector<double> bottom = series(c.directory, "pBedBottom"), top = series(c.directory, "pBedTop");
  const std::size_t n = std::min(bottom.size(), top.size()) - (running ? 1 : 0);  // series() gives at least one
  for (std::size_t k = 0; k < n; ++k) g.push_back(rho * (bottom[k] - top[k]) / (c.section.z_high - c.section.z_low));
  return g;
}

// A solve watched past its residual targets, as its log and monitors are being written.
class SettleWatch {
 public:
  explicit SettleWatch(const CaseInfo& c) : c_(c) {}
  // Why to stop the solve now ("settled" or "run_on_limit", FlowResult::stopped_by), or nothing
  // before its targets or while dp/L is still settling. Reads the iterations the log finished
  // since the last call (every one, since the residuals may dip below their targets between two
  // looks); `step` is the last finished iteration.
  std::optional<std::string> follow(long step) {
    std::istringstream finished(finished_since(c_.directory / "log.simpleFoam", read_));
    for (const Iteration& it : read_iterations(finished)) {
      if (reached_ == 0 && it.p_seen && it.res_u > 0.0 && it.res_u <= *c_.params.residual_u &&
          it.res_p <= *c_.params.residual_p)
        reached_ = it.step;
      its_.push_back(it);
    }
    if (reached_ == 0) return std::nullopt;
    std::vector<double> g;
    try {
      g = bed_gradients(c_, its_, true);
    } catch (const std::runtime_error&) {
      return std::nullopt;  // a monitor not written yet
    }
    if (g.size() >= 3 && std::isfinite(g.back()) && g.back() != 0.0 &&
        analysis::settled_within(analysis::iteration_error(g), c_.params.iteration_tolerance))
      return "settled";
    if (step >= 2 * reached_) return "run_on_limit";
    return std::nullopt;
  }
  long reached() const { return reached_; }  // the first iteration with both residuals at their targets (0: none yet)

 private:
  const CaseInfo& c_;
  std::streamoff read_ = 0;  // of the log: the bytes read
  std::vector<Iteration> its_;
  long reached_ = 0;
};

// Allrun's steps as GNU time logged them in log.time ("name seconds kB" per step; a failed
// step's extra line, and a machine without GNU time, give none).
std::vector<FlowResult::Step> allrun_steps(const fs::path& case_dir) {
  std::vector<FlowResult::Step> steps;
  std::ifstream in(case_dir / "log.time");
  for (std::string line; std::getline(in, line);) {
    std::istringstream row(line);
    FlowResult::Step s;
    double kb = 0.0;
    std::string rest;
    if (!(row >> s.name >> s.time_s >> kb) || row >> rest) continue;
    s.peak_memory_mb = kb / 1024.0;
    steps.push_back(s);
  }
  return steps;
}

// What Allrun's checkMesh printed: the cells, their total volume, and the faces of each patch
// (a patch left without faces anywhere is not listed). cells < 0: no checkMesh ran.
struct CheckMeshLog {
  long cells = -1;
  std::optional<double> volume_m3;
  std::map<std::string, long> patch_faces;
};
CheckMeshLog read_check_mesh_log(const fs::path& path) {
  CheckMeshLog out;
  std::ifstream in(path);
  bool in_patch_table = false;
  for (std::string line; std::getline(in, line);) {
    if (const auto at = line.find("cells:"); at != std::string::npos) out.cells = std::atol(line.c_str() + at + 6);
    if (const auto at = line.find("Total volume = "); at != std::string::npos) out.volume_m3 = std::atof(line.c_str() + at + 15);
    if (line.find("Patch") != std::string::npos && line.find("Faces") != std::string::npos) {
      in_patch_table = true;
      continue;
    }
    std::istringstream row(line);
    std::string name;
    long faces = 0;
    if (in_patch_table && row >> name >> faces)
      out.patch_faces[name] = faces;
    else
      in_patch_table = false;
  }
  return out;
}

// snappyHexMesh keeps the cells connected to the point inside the fluid. Where its cells do not
// fit the throats between the spheres, that region can miss the inlet or the outlet, and the
// solver then fails on the patch it lost: say so, and what makes finer cells.
void refuse_lost_ends(const CheckMeshLog& check, const CaseInfo& c) {
  std::vector<std::string> lost;
  for (const char* end : {"inlet", "outlet"})
    if (const auto it = check.patch_faces.find(end); it == check.patch_faces.end() || it->second == 0) lost.push_back(end);
  if (check.cells < 0 || lost.empty()) return;
  const std::string kept = check.volume_m3 && c.surface_volume_m3
                               ? fmt::format(" and hold {:.1f} % of the surface's fluid volume",
                                             100.0 * *check.volume_m3 / *c.surface_volume_m3)
                               : std::string();
  throw ConvergenceError(fmt::format(
      "snappyHexMesh's cells have no {0} faces{1}: the region they keep, around the point inside the fluid, does not "
      "reach the {0}, as happens where cells of {2:.3g} d at the surfaces (case.snappy_cell_d = {3}, "
      "case.snappy_level = {4}) do not fit the bed's narrowest throats; allowed: a smaller case.snappy_cell_d, a "
      "larger case.snappy_level, or gmsh's cells (case.mesher = \"gmsh\")",
      fmt::join(lost, " or "), kept, c.params.snappy_cell_d / std::pow(2.0, c.params.snappy_level),
      c.params.snappy_cell_d, c.params.snappy_level));
}

// simpleFoam stopped by a floating-point exception (OpenFOAM traps them): the solve diverged.
// Said as such, with the iteration it reached, rather than as a failed program.
void refuse_diverged(const fs::path& case_dir) {
  std::ifstream log(case_dir / "log.simpleFoam");
  std::stringstream text;
  text << log.rdbuf();
  if (text.str().find("Floating point exception") == std::string::npos && text.str().find("sigFpe") == std::string::npos)
    return;
  const std::vector<Iteration> its = read_iterations(text);
  throw ConvergenceError(fmt::format(
      "simpleFoam diverged (a floating-point exception{}); see {}/log.simpleFoam. The case, its mesh and the files "
      "before it are kept; allowed: a mesh that passes a stricter gate ([mesh.gate]), or a lower case.reynolds",
      its.empty() ? std::string() : fmt::format(" at iteration {}", its.back().step), case_dir.string()));
}

// The last line of a log that is not blank (Allrun's last words: which step failed).
std::string last_line(const fs::path& path) {
  std::ifstream in(path);
  std::string last;
  for (std::string line; std::getline(in, line);)
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

}  // namespace

std::optional<Divergence> DivergenceWatch::feed(std::istream& log) {
  for (const Iteration& it : read_iterations(log)) {
    if (found_) break;
    for (auto [field, r, least, target] : {std::tuple{"U", it.res_u, &least_u_, target_u_},
                                           std::tuple{"p", it.res_p, &least_p_, target_p_}}) {
      if (!(r > 0.0)) continue;  // not solved for in this iteration (yet)
      if (least->step > 0 && r > kDivergenceRise * std::max(least->residual, target)) {
        found_ = Divergence{field, least->step, least->residual, it.step, r};
        break;
      }
      if (r < least->residual) *least = {it.step, r};
    }
  }
  return found_;
}

std::optional<Divergence> DivergenceWatch::follow(const fs::path& path) {
  if (found_) return found_;
  std::istringstream finished(finished_since(path, read_));
  return feed(finished);
}

std::optional<Divergence> find_divergence(std::istream& log, double target_u, double target_p) {
  return DivergenceWatch(target_u, target_p).feed(log);
}

std::string missing_openfoam_program(int processors) {
  std::vector<std::string> programs = {"simpleFoam", "checkMesh"};
  if (processors > 1) programs.insert(programs.end(), {"decomposePar", "reconstructPar", "mpirun"});
  const char* path = std::getenv("PATH");
  for (const std::string& program : programs) {
    bool found = false;
    std::istringstream dirs(path ? path : "");
    for (std::string d; !found && std::getline(dirs, d, ':');)
      found = !d.empty() && ::access((fs::path(d) / program).c_str(), X_OK) == 0;
    if (!found) return program;
  }
  return {};
}

FlowResult run_case(const CaseInfo& c, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path& case_dir = c.directory;
  const int np = c.params.processors;
  const bool snappy = c.params.snappy_cells;
  const std::string cmd = fmt::format("'{}/Allrun' -np {} > '{}/log.Allrun' 2>&1", case_dir.string(), np,
                                      case_dir.string());
  // Allrun in the background; meanwhile the solver's log tells how far it is. The ETA assumes
  // the residuals keep falling geometrically to their targets, and follows the one furthest
  // from its target.
  auto run = std::async(std::launch::async, [&cmd] { return std::system(cmd.c_str()); });
  const double target_p = c.params.residual_p.value(), target_u = c.params.residual_u.value();
  double start_p = 0.0, start_u = 0.0;
  DivergenceWatch watch(target_u, target_p);
  std::optional<Divergence> diverging;
  SettleWatch settle(c);
  std::optional<std::string> stopped;   // why bedforge stopped the solve past its residual targets
  while (run.wait_for(std::chrono::milliseconds(500)) != std::future_status::ready) {
    const Iteration now = last_iteration(case_dir / "log.simpleFoam");
    if (now.step == 0 || now.res_p <= 0.0 || now.res_u <= 0.0) {
      progress.update(snappy ? "snappyHexMesh, then simpleFoam" : "preparing simpleFoam");
      continue;
    }
    if (!diverging && (diverging = watch.follow(case_dir / "log.simpleFoam"))) set_stop_at(case_dir, "writeNow");
    if (!diverging && !stopped && (stopped = settle.follow(now.step))) set_stop_at(case_dir, "writeNow");
    if (start_p == 0.0) start_p = std::max(now.res_p, 10.0 * target_p), start_u = std::max(now.res_u, 10.0 * target_u);
    const double done = std::min(std::log(start_p / now.res_p) / std::log(start_p / target_p),
                                 std::log(start_u / now.res_u) / std::log(start_u / target_u));
    progress.update(settle.reached() ? fmt::format("simpleFoam iteration {}, residuals at their targets; dp/L settling to {:g} %",
                                          now.step, 100.0 * c.params.iteration_tolerance)
                            : fmt::format("simpleFoam iteration {}, residuals U {:.1e} p {:.1e} (targets {:.0e}, {:.0e})",
                                          now.step, now.res_u, now.res_p, target_u, target_p),
                    std::clamp(done, 0.0, 1.0));
  }
  progress.finish();
  if (stopped) set_stop_at(case_dir, "endTime");  // the case as written, for a run by hand
  if (diverging) {
    const Divergence& d = *diverging;
    const Iteration last = last_iteration(case_dir / "log.simpleFoam");
    throw ConvergenceError(fmt::format(
        "simpleFoam diverging: the initial residual of {} rose from {:.2e} at iteration {} to {:.2e} at iteration {}, "
        "more than {:g} times the least it had reached; stopped at iteration {} with its fields written there (in "
        "{}/{} or, on more than one process, its processor*/{}) to show where; see {}/log.simpleFoam. The case and its "
        "mesh are kept; allowed: a mesh that passes a stricter gate ([mesh.gate]), or a lower case.reynolds",
        d.field, d.least, d.least_step, d.residual, d.step, kDivergenceRise, last.step, case_dir.string(), last.step,
        last.step, case_dir.string()));
  }
  const CheckMeshLog check = read_check_mesh_log(case_dir / "log.checkMesh");
  if (run.get() != 0) {
    if (snappy) refuse_lost_ends(check, c);
    refuse_diverged(case_dir);
    throw std::runtime_error(fmt::format("the OpenFOAM run failed ({}); see {}/log.Allrun and the logs next to it",
                                         last_line(case_dir / "log.Allrun"), case_dir.string()));
  }
  const double time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Convergence: SIMPLE's own message and, per iteration, the initial residuals and the time.
  std::ifstream log(case_dir / "log.simpleFoam");
  bool converged = false;
  const std::vector<Iteration> its = read_iterations(log, &converged);
  if (its.empty()) throw std::runtime_error(fmt::format("{}/log.simpleFoam holds no iteration", case_dir.string()));
  const long iterations = static_cast<long>(its.size());
  const double res_u = its.back().res_u, res_p = its.back().res_p;
  converged = converged || stopped.has_value();  // bedforge stopped it past the targets
  // Walls the flow slips along are mirror planes: the correlation's bed is then unbounded.
  const double a = c.params.slip_walls ? std::numeric_limits<double>::infinity() : c.aspect_ratio;
  const double rho = c.params.density_kg_m3, u = c.velocity_m_s, d = c.d_ref_m;
  const double zl = c.section.z_low, zh = c.section.z_high, re = c.params.reynolds;
  // The bed's pressure gradient per iteration (bed_gradients).
  const bool periodic = c.mean_velocity_m_s.has_value();
  const std::vector<double> gradients = bed_gradients(c, its, false);
  const std::size_t n = gradients.size();
  const double gradient = gradients.back();
  if (periodic && !(gradient > 0.0))
    throw std::runtime_error(fmt::format("{}/log.simpleFoam: meanVelocityForce drove the flow at a pressure gradient "
                                         "of {} Pa/m; please report it with the case",
                                         case_dir.string(), gradient));
  // Convergence of the quantity itself: what it would still move had the solve run on.
  const std::optional<analysis::IterationError> iteration =
      n >= 3 && std::isfinite(gradient) && gradient != 0.0 ? std::optional(analysis::iteration_error(gradients)) : std::nullopt;
  const double overall = periodic ? gradient * (zh - zl)
                                  : rho * (series(case_dir, "pInlet").back() - series(case_dir, "pOutlet").back());
  const double flow = series(case_dir, "flowRate").back();
  FlowResult r;
  r.mesher = snappy ? "snappyHexMesh" : c.params.polyhedra ? "gmsh polyhedral dual" : "gmsh tetrahedra";
  r.solved_cells = snappy || c.params.polyhedra ? -1 : c.cells;
  r.steps = allrun_steps(case_dir);
  if (snappy || c.params.polyhedra) {  // the cells Allrun made, as its checkMesh counted them
    r.solved_cells = check.cells;
    r.solved_volume_m3 = check.volume_m3;
    if (snappy && check.volume_m3 && c.surface_volume_m3) r.volume_lost = 1.0 - *check.volume_m3 / *c.surface_volume_m3;
  }
  // Convergence history: the residuals and the bed's pressure gradient against the solver's time.
  nlohmann::json history = nlohmann::json::array();
  for (std::size_t k = 0; k < its.size(); ++k) {
    nlohmann::json point = {{"iteration", k + 1}, {"time_s", its[k].time_s}, {"residual_U", its[k].res_u},
                            {"residual_p", its[k].res_p}};
    if (k < n) point["pressure_gradient_bed_pa_m"] = gradients[k];
    history.push_back(std::move(point));
  }
  r.time_s = time;
  r.solver_peak_memory_mb = children_peak_memory_mb();
  r.iterations = iterations;
  r.history = thin_history(history);
  r.converged = converged;
  r.stopped_by = stopped                         ? *stopped
                 : converged                     ? "residual_control"
                                                 : "iteration_cap";
  r.residual_u = res_u;
  r.residual_p = res_p;
  r.pressure_gradient_bed_pa_m = gradient;
  r.pressure_gradient_iteration = iteration;
  r.pressure_drop_inlet_outlet_pa = overall;
  r.flow_rate_m3_s = flow;
  r.flow_rate_relative_error = flow / (u * c.inlet_area_m2) - 1.0;
  // gmsh's inlet is the section as faceted or the flow rate set (kFlowRateTolerance): far more
  // off, the case drove another flow than the one its dp/L is quoted at.
  if (!periodic && !snappy && std::abs(r.flow_rate_relative_error) > kFlowRateTolerance)
    throw std::runtime_error(fmt::format("{}: the flow rate through the outlet, {:.6g} m3/s, is {:+.1f} % off the "
                                         "superficial velocity times the section ({:.6g} m3/s); please report it with "
                                         "the case",
                                         case_dir.string(), flow, 100.0 * r.flow_rate_relative_error,
                                         u * c.inlet_area_m2));
  const ForceZ walls = c.walls ? last_force_z(case_dir, "forceWalls") : ForceZ{};
  const ForceZ particles = c.particles ? last_force_z(case_dir, "forceParticles") : ForceZ{};
  r.drag.walls_n = walls.total, r.drag.walls_viscous_n = walls.viscous;
  r.drag.particles_n = particles.total, r.drag.particles_viscous_n = particles.viscous;
  r.drag.particles_by_gap = c.gap_bands;
  if (c.wall_faces_beyond_section > 0) {
    const ForceZ ends = last_force_z(case_dir, "forceWallsEnds");
    r.drag.walls_ends_n = ends.total, r.drag.walls_ends_viscous_n = ends.viscous;
  }
  // The section's mean pressure (Pa), linear between its planes: p_low - gradient (z - z_low).
  const double p_low = periodic ? 0.0 : rho * series(case_dir, "pBedBottom")[n - 1],
               mean_gradient = periodic ? 0.0 : gradient;
  for (GapBand& b : r.drag.particles_by_gap) {
    if (b.faces == 0) continue;  // no forces object
    const ForceZ f = last_force_z(case_dir, b.force_object());
    b.drag_n = f.total, b.viscous_n = f.viscous;
    b.form_n = f.total - f.viscous - (p_low * b.area_z_m2 - mean_gradient * (b.moment_z_m3 - zl * b.area_z_m2));
  }
  // What pushes the fluid: the pressure on the inlet and outlet, or in a periodic section the
  // driving gradient over the fluid's volume (the cells solved on).
  if (periodic)
    r.drag.push_inlet_outlet_n = rho * its[n - 1].driving_gradient * r.solved_volume_m3.value_or(c.fluid_volume_m3.value_or(0.0));
  else
    r.drag.push_inlet_outlet_n = -(last_force_z(case_dir, "forceInlet").total + last_force_z(case_dir, "forceOutlet").total);
  if (c.stokes_array) {
    r.van_der_hoef_pa_m = c.stokes_array->pa_m;
    r.ratio_to_van_der_hoef = gradient / c.stokes_array->pa_m;
  }
  if (c.bound) {
    r.bound = c.bound;
    r.ratio_to_bound = gradient / c.bound->pa_m;
  }
  if (c.exact_pressure_gradient_pa_m) {
    r.exact_pa_m = c.exact_pressure_gradient_pa_m;
    r.relative_error_to_exact = gradient / *r.exact_pa_m - 1.0;
    return r;
  }
  if (const std::optional<double> eps = c.section.void_fraction) {
    r.eisfeld_schnitzlein_pa_m = analysis::pressure_gradient(analysis::eisfeld_schnitzlein_f(re, *eps, a), *eps, rho, u, d);
    r.ratio_to_eisfeld_schnitzlein = gradient / *r.eisfeld_schnitzlein_pa_m;
    r.void_fraction_section = eps;
  }
  const double eps_bed = c.section.void_fraction_bed;
  r.eisfeld_schnitzlein_bed_pa_m =
      analysis::pressure_gradient(analysis::eisfeld_schnitzlein_f(re, eps_bed, a), eps_bed, rho, u, d);
  r.ratio_to_eisfeld_schnitzlein_bed = gradient / r.eisfeld_schnitzlein_bed_pa_m;
  r.void_fraction_section_bed = eps_bed;
  r.wall_share_of_drag_eisfeld_schnitzlein = analysis::wall_wetted_area_share(eps_bed, a);
  return r;
}

}  // namespace bedforge::cases
