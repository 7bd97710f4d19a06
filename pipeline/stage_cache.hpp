#pragma once
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/scene.hpp"

namespace bedforge::pipeline {

// What a run writes into its directory.
struct Wants {
  bool positions = false;  // bed.csv
  bool vtp = false;        // bed.vtp
  bool analysis = false;   // profiles and contacts
  bool stl = false;        // the surface's STL and VTP files (also for the snappyHexMesh route)
  bool mesh = false;       // fluid.msh
  bool case_ = false;      // the OpenFOAM case in case/
  bool case_on_mesh = true;  // the case solves on the mesh stage's cells (not on snappyHexMesh's)
  bool study = false;        // a convergence study follows the case ([case.convergence] levels)
};
// `bedforge run`: the scene's [outputs]. `bedforge pack` and `import`: the bed only.
Wants run_wants(const Scene& scene);
Wants pack_wants(const Scene& scene);

// Each stage's cache key (see stage_key): a hash of its own scene sections and of the key of
// the stage it builds on, so a change upstream reaches every later stage. The pack key covers
// [container], [particles], [packing], the bedforge version and an imported file's content; the
// case's builds on the mesh's, or on the surface's when snappyHexMesh makes its cells, and leaves
// out [case.convergence]: the study keys its levels itself (convergence_study.hpp), so a changed
// study keeps the solved case. The study's key is the case's with [case.convergence].
struct StageKeys {
  std::string pack, analysis, surface, mesh, case_, study;
};
StageKeys stage_keys(const Scene& scene);

// What one stage does in a run.
struct StagePlan {
  bool involved = false;  // the run reports this stage
  bool build = false;     // made anew
  nlohmann::json reused;  // the earlier run's entry, marked "reused", when involved and not built
};

// The plan of a run in a directory that may hold an earlier one. Decided from the last stage
// backwards: a stage whose key matches and whose files are there is reused, and what it was made
// from is built only when another stage needs it in memory. A mesh is made from the surface in
// memory, never from its STL read back, so building a mesh builds its surface. A case on
// snappyHexMesh's cells needs no mesh, only the surface's files. A case reused for a study must
// carry one (its finest level) and, when the study changed, needs the bed for the levels it may
// have to build.
struct RunPlan {
  StagePlan pack, analysis, surface, mesh, case_;
  bool load_bed = false;       // read the reused bed from bed.csv: a stage built after it needs it
  bool load_mesh = false;      // read the reused mesh from fluid.msh: the case is rebuilt on it
  bool write_bed_csv = false;  // bed.csv is wanted and new or missing
  bool write_bed_vtp = false;
  bool redo_study = false;     // the case is reused but its study changed: redone from its finest level
};
// `previous`: the earlier report.json (null for none, or to redo everything); `exists(name)`:
// whether the directory holds that file.
RunPlan plan_run(const Wants& wants, const StageKeys& keys, const nlohmann::json& previous,
                 const std::function<bool(const std::string&)>& exists);

}  // namespace bedforge::pipeline
