#pragma once
#include <nlohmann/json.hpp>
#include <filesystem>
#include <istream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "analysis/iteration_error.hpp"
#include "cases/case_writer.hpp"
#include "core/progress.hpp"

namespace bedforge::cases {

// The flow solved in a case: the solver's convergence and the bed's pressure gradient.
struct FlowResult {
  double time_s = 0.0;                   // wall time of Allrun
  double solver_peak_memory_mb = 0.0;    // OpenFOAM's largest process
  std::string mesher;                    // what made the cells solved on: "gmsh tetrahedra", "gmsh polyhedral dual", "snappyHexMesh"
  long solved_cells = -1;                // the cells solved on, as Allrun's checkMesh counted them (-1: no checkMesh ran)
  std::optional<double> solved_volume_m3;  // their total volume, as that checkMesh summed it
  // snappyHexMesh's cells: 1 - their volume / the surface's, the fluid they do not fill
  // (throats and gaps narrower than the cells, dropped).
  std::optional<double> volume_lost;
  // Allrun's steps, each with its wall time and its largest process's peak memory (from GNU
  // time when the machine has it: empty otherwise). On N processes that is the largest rank's.
  struct Step {
    std::string name;
    double time_s = 0.0, peak_memory_mb = 0.0;
  };
  std::vector<Step> steps;
  long iterations = 0;
  bool converged = false;                // the residual targets reached (SIMPLE's verdict, or bedforge's stop past them)
  // What ended the solve: "settled" (the targets reached and dp/L settled to
  // case.iteration_tolerance), "run_on_limit" (the targets reached, dp/L not settled within as many
  // iterations again), "residual_control" (SIMPLE's own, at kResidualControlShare of the targets),
  // "iteration_cap" (case.iterations).
  std::string stopped_by;
  double residual_u = 0.0, residual_p = 0.0;  // the last iteration's initial residuals
  // Over the bed section; in a periodic section the driving gradient, scaled to the flow rate set
  // (case_runner.cpp says why).
  double pressure_gradient_bed_pa_m = 0.0;
  // What the gradient would still have moved had the solve run on, from how its last changes
  // shrank (unset with fewer than 3 iterations); its last change, over the last block of
  // iterations (a tenth of them, at least 10), is the report's pressure_gradient_change_last_block.
  std::optional<analysis::IterationError> pressure_gradient_iteration;
  double pressure_drop_inlet_outlet_pa = 0.0;
  double flow_rate_m3_s = 0.0, flow_rate_relative_error = 0.0;
  Drag drag;  // the forces on the walls and particles, and the push through inlet and outlet
  // A case with a known answer (no correlation is compared): the exact gradient and the relative
  // error dp/L / exact - 1. Otherwise unset and the correlation's fields below are filled.
  std::optional<double> exact_pa_m;
  double relative_error_to_exact = 0.0;
  // A treated simple cubic column or array (CaseInfo::bound): its untreated answer, a bound from
  // below or above, and dp/L over it; the correlation's fields below are filled too.
  std::optional<KnownBound> bound;
  double ratio_to_bound = 0.0;
  // A random array's Stokes drag (CaseInfo::stokes_array): van der Hoef et al.'s gradient and
  // dp/L over it.
  std::optional<double> van_der_hoef_pa_m, ratio_to_van_der_hoef;
  // The correlation at the section's meshed void fraction, when known (not on snappyHexMesh's cells).
  std::optional<double> eisfeld_schnitzlein_pa_m, ratio_to_eisfeld_schnitzlein, void_fraction_section;
  // The same at the section's exact void fraction of the spheres as packed: the bed the
  // correlation describes, whatever the contact treatment and the facets did to it.
  double eisfeld_schnitzlein_bed_pa_m = 0.0;
  double ratio_to_eisfeld_schnitzlein_bed = 0.0;
  double void_fraction_section_bed = 0.0;
  // The wall's share of the wetted area at that void fraction: its share of the drag in the
  // correlation's wall term (analysis::wall_wetted_area_share), to hold the measured share against.
  double wall_share_of_drag_eisfeld_schnitzlein = 0.0;
  nlohmann::json history;                // per iteration: residuals and the bed's gradient against time
  nlohmann::json to_json() const;        // the case entry's "flow"
};

// The first of the OpenFOAM programs Allrun needs on `processors` processes (simpleFoam and
// checkMesh; decomposePar, reconstructPar and mpirun on more than one) that is not on PATH;
// empty when all are.
std::string missing_openfoam_program(int processors);

// The most the flow rate through the outlet may differ from the superficial velocity times the
// section on gmsh's cells outside a periodic section before run_case calls it a defect: the
// inlet's faceting takes off a few per cent on coarse meshes (-0.64 % on the empty tube of 2 d at
// 0.2 d, -2.3 % on its coarsest level of 0.4 d; an 8-gon would lose 10 %), a clip window's
// inlet that carried only the fluid's share took off 60 %.
inline constexpr double kFlowRateTolerance = 0.1;

// A solve turning back: the initial residual of U (the largest of its components) or of p (its
// first solve in an iteration) past kDivergenceRise times the least it had reached, or times its
// target where the least is below the target (noise there is no divergence).
struct Divergence {
  std::string field;       // "U" or "p"
  long least_step = 0;     // the iteration of the least residual before the rise
  double least = 0.0;
  long step = 0;           // the first iteration past the rise
  double residual = 0.0;
};
// 10: on 56 solves that converged (tetrahedra and polyhedra; Re_p 0.01 to 100; beds in one piece
// and in 2 to 16, periodic sections, a random array; docs/findings.md 2026-12-06) neither residual
// ever rose past 1.3 times its least; the one that diverged slowly (a = 14, N = 1e4, 4 pieces)
// rose 156 (p) and 235 (U) times with no floating-point exception in 70 iterations, and would
// have run on to case.iterations (some 11 hours there).
inline constexpr double kDivergenceRise = 10.0;

// Watches a simpleFoam log for a divergence, with the targets SIMPLE stops at (residual_u,
// residual_p): each iteration is read once, so that watching a run of many iterations stays linear
// in its log.
class DivergenceWatch {
 public:
  DivergenceWatch(double target_u, double target_p) : target_u_(target_u), target_p_(target_p) {}
  // The first divergence among the iterations of `log` (text continuing what was fed before,
  // whole iterations); std::nullopt while there is none.
  std::optional<Divergence> feed(std::istream& log);
  // The same for the log file `path` being written: reads what was added since the last call, up
  // to its last "Time = " line (the iterations before it are finished).
  std::optional<Divergence> follow(const std::filesystem::path& path);

 private:
  struct Least {
    long step = 0;
    double residual = std::numeric_limits<double>::infinity();
  };
  double target_u_, target_p_;
  Least least_u_, least_p_;
  std::optional<Divergence> found_;
  std::streamoff read_ = 0;  // of the file follow() reads: the bytes fed
};

// The first divergence in the whole simpleFoam log `log` (DivergenceWatch::feed).
std::optional<Divergence> find_divergence(std::istream& log, double target_u, double target_p);

// Runs `case.directory/Allrun` (OpenFOAM on PATH, WM_PROJECT_DIR defaulting to Debian's) and
// reads back the solver's convergence and the pressure drop, compared with Eisfeld &
// Schnitzlein at the section's own void fraction. Shows the solver's iteration on `progress`
// while it runs, and watches it for a divergence (DivergenceWatch): the run is then stopped at
// that iteration with its fields written (controlDict's stopAt set to writeNow, which OpenFOAM
// reads while it runs) and ConvergenceError says where, rather than the solve running on to
// case.iterations. Once both residuals are at their targets it goes on watching dp/L and stops
// the solve the same way when it has settled to case.iteration_tolerance (analysis::
// settled_within), or when it has run as many iterations again as it took to reach them; the
// controlDict then gets its stopAt endTime back. ConvergenceError also when the solver stopped on a floating-point exception,
// and when snappyHexMesh's cells lost the inlet or the outlet (the
// fluid they kept does not reach it), naming the settings that make finer cells;
// std::runtime_error naming the log and Allrun's last words when another step fails.
FlowResult run_case(const CaseInfo& c, Progress& progress);

}  // namespace bedforge::cases
