#pragma once
#include <filesystem>

#include "pipeline/console.hpp"
#include "pipeline/scene.hpp"
#include "pipeline/stage_cache.hpp"

namespace bedforge::pipeline {

struct RunOptions {
  Wants wants;             // what the run writes (run_wants or pack_wants)
  bool overwrite = false;  // replace DIR/case when the case must be made again
  bool force = false;      // redo every stage, even those DIR holds for unchanged inputs
};

// Runs the stages `options.wants` needs for `scene` into `dir` (created if missing): DIR/
// scene.toml, report.json, summary.txt and each stage's files. A stage an earlier run left in
// DIR with the same key and its files is reused (plan_run), and says so on `console`; an
// unchanged rerun builds nothing. The case is refused before any work when it must be made
// again, DIR/case exists and `overwrite` is not set. Files are written only once every stage
// before the case has succeeded, the case itself through a temporary directory. A solved case's
// answer (pressure_drop_answer) is printed last, kept in report.json (stages.case.answer) and
// summary.txt, and drawn in DIR/pressure_drop.svg. When the scene asks for the case to be run
// and OpenFOAM is not installed, the run says so first, writes the case unsolved and then throws
// NotSolvedError.
void run_scene(const Scene& scene, const std::filesystem::path& dir, const RunOptions& options, const Console& console);

}  // namespace bedforge::pipeline
