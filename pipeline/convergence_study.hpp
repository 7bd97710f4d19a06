#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/grid_convergence.hpp"
#include "analysis/iteration_error.hpp"
#include "core/bed.hpp"
#include "core/report.hpp"
#include "pipeline/case_stage.hpp"
#include "pipeline/console.hpp"
#include "pipeline/scene.hpp"

namespace bedforge::pipeline {

// One mesh of a convergence study and the flow on it.
struct StudyLevel {
  int level = 0;              // 1 the finest (the scene's own mesh), then coarser
  double scale = 1.0;         // its lengths over the scene's: ratio^(level - 1)
  long cells = 0;             // the cells the flow was solved on (the polyhedral dual's, by default)
  double cell_size_m = 0.0;   // (V / N)^(1/3), V the volume of the mesh's cells
  double pressure_gradient_pa_m = 0.0;
  bool converged = false;     // the solver's own verdict
  // What its dp/L would still have moved had the solve run on (cases::FlowResult's; unset in
  // reports before 2026-12-07).
  std::optional<analysis::IterationError> iteration;
  std::string stopped_by;     // what ended its solve (cases::FlowResult's; empty in older reports)
  long cells_failing_check_mesh = 0;  // polyhedra that fail checkMesh's limits (meshing::check_polyhedra)
  // The drag by kind, and with case.drag_by_gap_d the particles' by the gap at their faces
  // (cases::FlowResult): where the level's error sits.
  cases::Drag drag;
  double time_s = 0.0;        // this run's time for the level: surface, mesh and flow of a coarser one
                              // (every sizing attempt); the flow alone of the finest (its surface and
                              // mesh may be reused)
  double own_time_s = 0.0;    // surface, mesh and flow of the mesh solved on, each once: what the level
                              // costs as a run of its own, for error against time (a level that
                              // failed has none)
  std::string failure;        // why the level gave no value (empty when it did)
  std::optional<double> exact_pa_m;  // an empty container's known answer (the case's)
  std::optional<cases::KnownBound> bound;  // a treated lattice's: its untreated answer (the case's)
  // The scales tried to bring a coarser level's cells to their target size, with the cell size
  // each mesh promised ((fluid volume / cells to solve)^(1/3), m), the last one solved.
  std::vector<std::pair<double, double>> sizing;
  double alpha = 1.0;      // the sizing's exponent (cell size ~ scale^alpha) after this level: the next one's start
  std::string cache_key;   // the finest's: the case stage's; a coarser one's: its finer one's, the ratio and its number
  bool reused = false;     // taken from the earlier run in the directory, not solved again
};
// A level as ConvergenceStudy::to_json wrote it; `exact_pa_m` the study's known answer, if any.
StudyLevel study_level_from_json(const nlohmann::json& level, std::optional<double> exact_pa_m);

// The pressure drop's discretisation error from the flow solved on the scene's mesh and on
// coarser ones: the levels and the verdict on the finest three that gave a value.
struct ConvergenceStudy {
  std::vector<StudyLevel> levels;
  bool complete = false;                 // three usable finest levels in a row
  analysis::GridConvergence convergence; // when complete
  // With four or more levels that gave a value: the least-squares power law over all of them,
  // which says how far the levels stray from the one the finest three imply.
  std::optional<analysis::PowerLawFit> fit;
  std::string conclusion;                // what the study could and could not conclude
  // A known answer's gradient (Pa/m; an empty container's, a simple cubic column's): each level's
  // error against it and the order of those errors, the verification of the whole route.
  std::optional<double> exact_pa_m;
  double order_from_exact = 0.0;         // observed_order over the levels that gave a value
  // A treated simple cubic column's or array's: its untreated answer, which the extrapolation
  // (the treated bed's mesh-independent value) must not pass (cases::KnownBound).
  std::optional<cases::KnownBound> bound;
  nlohmann::json to_json() const;
};

// The surface and mesh settings of a level whose lengths are `scale` times the scene's: the
// surface's edge and contact edge, the mesh's largest cell, the prism layers' thickness (their
// room rule kept at the coarsest level's lengths: layers_for_study), and the edge across narrow gaps
// (gap / cells_per_gap: cells_per_gap is divided by `scale`, and the gaps it refines stay the
// same). Celik et al.'s procedure needs meshes refined alike everywhere; with cells_per_gap
// kept, the gaps' cells were the same on every level.
struct LevelLengths {
  meshing::SurfaceParams surface;
  meshing::VolumeMeshParams mesh;
};
LevelLengths level_lengths(const Scene& scene, double scale);

// The prism layers of a study's finest level (the scene's own mesh): with `study` levels > 0 and
// layers, room_scale is the scale of the coarsest level's lengths as first guessed, so that the
// finest decides its stacks as the coarsest will and level_lengths carries that to every level
// (room_scale / scale): the same region layered on every level. Else `layers` unchanged.
meshing::PrismLayerParams layers_for_study(meshing::PrismLayerParams layers, const cases::CaseParams::Convergence& study);

// Level `level` (lengths x `scale`) from its solved case, its time the flow's; `surface_mesh_s`
// the time its surface and mesh took to make.
StudyLevel study_level(const CaseStage& solved, int level, double scale, double surface_mesh_s);

// The study of [case.convergence] on `bed` (m): `finest` is the scene's own level, already
// solved (study_level(case, 1, 1.0, ...)). Each coarser level k scales the scene's lengths
// (level_lengths) by the factor that makes its cells ratio^(k - 1) times the size of the
// finest's (searched: up to 4 surfaces and meshes, to within 3 %), builds its surface and mesh
// in memory and solves its case in `dir`/level_k; with mesh.pieces > 1 its ranks make it in
// pieces instead (case_pieces), from the bed and the scene with the level's lengths written to
// `dir`/level_k, its case in `dir`/level_k/case, sized on the pieces' cells and then solved. A level that fails (a gate, the solver) is
// reported with its reason, and the others go on. A level of `earlier` (the study an earlier
// run left in `dir`, as to_json wrote it; null for none) with the same cache key, whose case is
// still there, is taken as it is: adding a level, or going back to fewer, solves nothing again.
// Level directories beyond the study's levels are removed.
ConvergenceStudy convergence_study(const Scene& scene, const Bed& bed, const StudyLevel& finest,
                                   const std::filesystem::path& dir, const Console& console,
                                   const nlohmann::json& earlier = nullptr);

// The finest level of a study from the scene's solved case: `report` is the run's, whose surface
// and mesh stages made the solved mesh (their times count in the level's own); `case_key` the
// case stage's cache key (empty when the case is not cached).
StudyLevel finest_level(const CaseStage& solved, const Report& report, const std::string& case_key);

// Runs the study of [case.convergence] from `finest` into `dir`/convergence, reusing the levels
// of `earlier` (an earlier run's study in `dir`, or null) that still hold, and puts it in the
// case's report entry: its "convergence" and a summary that ends with the study's conclusion,
// which is printed (an earlier study's conclusion there is replaced). Returns the study.
ConvergenceStudy add_convergence_study(const Scene& scene, const Bed& bed, const StudyLevel& finest, const nlohmann::json& earlier,
                           const std::filesystem::path& dir, const Console& console, nlohmann::json& case_entry);

// The case's report entry without its study (its "convergence" and the summary's conclusion):
// for a case reused by a run that asks for none.
void remove_convergence_study(nlohmann::json& case_entry);

}  // namespace bedforge::pipeline
