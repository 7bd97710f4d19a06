// A scene run through the pipeline library, no command line: what an unchanged rerun, a changed
// section and files deleted by hand make it do.
#include "pipeline/run_scene.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "analysis/grid_convergence.hpp"
#include "core/error.hpp"
#include "pipeline/mesh_stage.hpp"
#include "pipeline/pack_stage.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace bedforge;
using namespace bedforge::pipeline;

namespace {

// Shrunk contacts, no refinement across gaps: the cheapest surface (a scene's defaults bridge
// the contacts and refine their gaps).
const std::string kShrunk = "[contacts]\ntreatment = \"shrink\"\n";
const std::string kPlainSurface = "contact_edge_length_d = 0.033\ncells_per_gap = 0\n";

// 12 spheres in a = 3 with a coarse surface: every stage, in seconds. `extra` adds sections;
// `surface` replaces the surface and contact settings.
Scene small_scene(const std::string& outputs, const std::string& extra = "",
                  const std::string& surface = kShrunk + "[surface]\nedge_length_d = 0.1\n" + kPlainSurface) {
  const std::string text = "[container]\ndiameter_d = 3\n[particles]\ncount = 12\ndiameter_m = 0.002\n" + surface +
                           "[mesh]\nthreads = 1\n[outputs]\nfiles = [" + outputs + "]\n" + extra;
  return read_scene(parse_scene_text(text, "small.toml"), "small.toml");
}

// For flow studies: gaps of 6 % of a diameter at contacts (3 % at the wall) leave room for
// coarse wall facets (0.15 d and coarser), so each solve takes seconds. Measured on 2026-11-24:
// at 0.15 d and ratio 1.3 each level converged in about 90 iterations; at 0.2 d and 1.4 the
// coarsest level stalled in one of two runs (gmsh's mesh differs between builds).
const std::string kOpenSurface = kShrunk + "shrink_factor = 0.94\n[surface]\nedge_length_d = 0.15\n" + kPlainSurface;

// The empty tube's coarser levels (1.3 k to 2.7 k polyhedra): twice the largest error measured
// on such meshes, -2.2 % at 1.3 k cells (2026-11-24; the errors differ from mesh to mesh since
// gmsh's meshes do).
const double kCoarseTubeError = 0.044;

// What a run printed and which stages it built, from the report's "reused" marks.
struct RunOutcome {
  std::string printed;
  nlohmann::json stages;
  bool built(const std::string& stage) const { return stages.contains(stage) && !stages[stage].value("reused", false); }
};

RunOutcome run(const Scene& scene, const fs::path& dir, bool overwrite = false) {
  const Console quiet_progress{false, false};
  testing::internal::CaptureStdout();
  try {
    run_scene(scene, dir, {run_wants(scene), overwrite, false}, quiet_progress);
  } catch (...) {
    testing::internal::GetCapturedStdout();
    throw;
  }
  RunOutcome r{testing::internal::GetCapturedStdout(), nullptr};
  std::ifstream report(dir / "report.json");
  r.stages = nlohmann::json::parse(report)["stages"];
  return r;
}

fs::file_time_type written(const fs::path& p) { return fs::last_write_time(p); }

// A shipped example scene with `overrides` applied.
Scene example_scene(const std::string& name, const std::vector<Override>& overrides = {}) {
  const fs::path file = fs::path(BEDFORGE_SOURCE_DIR) / "scenes/examples" / name;
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  toml::table table = parse_scene_text(text.str(), file.string());
  apply_overrides(table, overrides);
  return read_scene(table, file.string(), file.parent_path());
}

}  // namespace

TEST(RunScene, ACaseOnlySceneRerunUnchangedDoesNoWork) {
  // The defect a new user met: outputs naming "case" but not "mesh", run twice.
  const fs::path dir = test_support::fresh_dir("case_only");
  const Scene scene = small_scene("\"case\"");
  const RunOutcome first = run(scene, dir);
  for (const char* stage : {"pack", "surface", "mesh", "case"}) EXPECT_TRUE(first.built(stage)) << stage;
  EXPECT_FALSE(fs::exists(dir / "fluid.msh"));
  const auto points = written(dir / "case/constant/polyMesh/points");

  const RunOutcome again = run(scene, dir);  // no --overwrite needed
  for (const char* stage : {"pack", "surface", "mesh", "case"}) {
    EXPECT_FALSE(again.built(stage)) << stage;
    EXPECT_NE(again.printed.find(std::string(stage) + ": reused"), std::string::npos) << again.printed;
  }
  EXPECT_EQ(again.printed.find("cells"), std::string::npos) << "a stage ran: " << again.printed;
  EXPECT_EQ(written(dir / "case/constant/polyMesh/points"), points);
  EXPECT_EQ(again.stages["case"]["cache_key"], first.stages["case"]["cache_key"]);
}

TEST(RunScene, OnlyTheCaseChangedMakesTheCaseAgainOnTheSameBed) {
  const fs::path dir = test_support::fresh_dir("case_changed");
  const RunOutcome first = run(small_scene("\"positions\", \"mesh\", \"case\""), dir);
  const std::string bed = first.stages["pack"]["cache_key"];
  const auto msh = written(dir / "fluid.msh");
  const Scene faster = small_scene("\"positions\", \"mesh\", \"case\"", "[case]\nreynolds = 10\n");
  // The case in DIR was made with other settings: replaced only when asked, refused before any work.
  EXPECT_THROW(run(faster, dir), InputError);
  const RunOutcome second = run(faster, dir, true);
  EXPECT_TRUE(second.built("case"));
  EXPECT_FALSE(second.built("mesh") || second.built("surface") || second.built("pack"));
  EXPECT_EQ(written(dir / "fluid.msh"), msh);
  EXPECT_EQ(second.stages["pack"]["cache_key"], bed);
  EXPECT_EQ(second.stages["case"]["parameters"]["reynolds"], 10.0);
}

TEST(RunScene, OnlyTheMeshChangedMeshesAgainWithoutPacking) {
  const fs::path dir = test_support::fresh_dir("mesh_changed");
  const RunOutcome first = run(small_scene("\"positions\", \"mesh\""), dir);
  const Scene coarser = small_scene("\"positions\", \"mesh\"", "[mesh.gate]\nmax_skewness = 5\n");
  const RunOutcome second = run(coarser, dir);
  EXPECT_TRUE(second.built("mesh") && second.built("surface"));  // a mesh is made from the surface in memory
  EXPECT_FALSE(second.built("pack"));
  EXPECT_NE(second.stages["mesh"]["cache_key"], first.stages["mesh"]["cache_key"]);
  EXPECT_EQ(second.stages["mesh"]["parameters"]["gate"]["max_skewness"], 5.0);
}

TEST(RunScene, FilesDeletedByHandAreMadeAgain) {
  const fs::path dir = test_support::fresh_dir("deleted");
  const Scene scene = small_scene("\"positions\", \"vtp\", \"analysis\", \"mesh\", \"case\"");
  run(scene, dir);
  const std::string vtp = [&] {
    std::ifstream in(dir / "bed.vtp");
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }();
  fs::remove(dir / "bed.vtp");
  fs::remove(dir / "radial_profile.csv");
  fs::remove_all(dir / "case");
  const RunOutcome again = run(scene, dir);
  EXPECT_FALSE(again.built("pack") || again.built("surface") || again.built("mesh"));
  EXPECT_TRUE(again.built("analysis") && again.built("case"));
  EXPECT_TRUE(fs::exists(dir / "radial_profile.csv") && fs::exists(dir / "case/Allrun"));
  std::ifstream in(dir / "bed.vtp");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), vtp);  // the same bed, read back from bed.csv
}

// [case.convergence]: the scene's mesh and three coarser ones, each solved; the verdict is the
// grid-convergence procedure's on the finest three levels' own numbers, and the least-squares
// power law the fit's on all four.
TEST(RunScene, AConvergenceStudySolvesCoarserMeshesOfTheSameBed) {
  const fs::path dir = test_support::fresh_dir("convergence");
  const Scene scene =
      small_scene("\"case\"", "[case]\nrun = true\n[case.convergence]\nlevels = 4\nratio = 1.3\n",
                  kShrunk + "shrink_factor = 0.94\n[surface]\nedge_length_d = 0.1\n" + kPlainSurface);
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& study = r.stages["case"]["convergence"];
  ASSERT_EQ(study["levels"].size(), 4u) << study.dump();
  for (int k = 0; k < 4; ++k) {
    const auto& level = study["levels"][k];
    ASSERT_FALSE(level.contains("failure")) << level.dump();
    EXPECT_EQ(level["level"], k + 1);
  }
  // Each coarser level's solved cells are 1.3 times the size of the finer one's: the sizing
  // search stops within 3 % of its target, on the points of the tetrahedra (one polyhedron each).
  // The sizing measures gmsh's tetrahedra; the case first cuts the flat ears that gmsh leaves on
  // some runs and not others (meshing/volume/flat_ears.hpp), slivers whose volume is far below one
  // cell's: so the solved size is at most the predicted one and less than a cell's volume below it
  // (a CI run of 2026-12-07 measured 1e-6 of the volume, 0.5 % of one of its 5,395 cells).
  for (int k = 1; k < 4; ++k) {
    const auto& level = study["levels"][k];
    const double h = level["cell_size_m"].get<double>(), h1 = study["levels"][0]["cell_size_m"].get<double>();
    EXPECT_NEAR(h / h1, std::pow(1.3, k), 0.03 * std::pow(1.3, k)) << level.dump();
    const double predicted = level["sizing"].back()["predicted_cell_size_m"].get<double>();
    const double one_cell = 1.0 / (3.0 * level["cells"].get<double>());  // of h, as d(h^3)/h^3 = 3 dh/h
    EXPECT_GE(predicted, h * (1.0 - 1e-12)) << level.dump();
    EXPECT_LT(predicted - h, one_cell * h) << level.dump();
  }
  // The scene's own mesh is the finest; the flow is solved on its polyhedral dual.
  EXPECT_EQ(study["levels"][0]["cells"], r.stages["case"]["flow"]["mesh"]["cells"]);
  EXPECT_EQ(r.stages["case"]["flow"]["mesh"]["mesher"], "gmsh polyhedral dual");
  // The correlation is also taken at the bed's exact void fraction, of the spheres as packed:
  // below the meshed one, since shrinking and inscribed facets only take solid away.
  const auto& flow = r.stages["case"]["flow"];
  EXPECT_LT(flow["void_fraction_section_bed"].get<double>(), flow["void_fraction_section"].get<double>());
  EXPECT_EQ(flow["void_fraction_section_bed"], r.stages["case"]["section"]["void_fraction_bed"]);
  EXPECT_EQ(study["levels"][0]["pressure_gradient_bed_pa_m"], r.stages["case"]["flow"]["pressure_gradient_bed_pa_m"]);
  for (int k = 1; k < 4; ++k) {
    EXPECT_LT(study["levels"][k]["cells"].get<long>(), study["levels"][k - 1]["cells"].get<long>()) << k;
    EXPECT_GT(study["levels"][k]["cell_size_m"].get<double>(), study["levels"][k - 1]["cell_size_m"].get<double>());
  }
  // A level's own cost is one surface, mesh and flow: the finest's adds the run's surface and
  // mesh stages to its flow; a coarser one's is its last sizing attempt and its flow, within the
  // level's whole time, which counts every attempt.
  const auto& stages = r.stages;
  EXPECT_DOUBLE_EQ(study["levels"][0]["own_time_s"].get<double>(),
                   stages["surface"]["time_s"].get<double>() + stages["mesh"]["time_s"].get<double>() +
                       stages["case"]["time_s"].get<double>());
  for (int k = 1; k < 4; ++k) {
    const auto& level = study["levels"][k];
    EXPECT_GT(level["own_time_s"].get<double>(), 0.0) << level.dump();
    EXPECT_LE(level["own_time_s"].get<double>(), level["time_s"].get<double>()) << level.dump();
    // Sized at the first attempt, the level's whole time is that surface, mesh and flow, and
    // little else (directories, the sizing arithmetic): its own time is nearly all of it.
    if (level["sizing"].size() == 1) {
      EXPECT_GT(level["own_time_s"].get<double>(), 0.95 * level["time_s"].get<double>()) << level.dump();
    }
  }
  ASSERT_TRUE(study["complete"].get<bool>()) << study.dump();
  std::vector<bedforge::analysis::GridLevel> levels;
  for (const auto& l : study["levels"])
    levels.push_back({l["cell_size_m"].get<double>(), l["pressure_gradient_bed_pa_m"].get<double>()});
  EXPECT_EQ(study["grid_convergence"], bedforge::analysis::grid_convergence({levels[0], levels[1], levels[2]}).to_json());
  EXPECT_EQ(study["least_squares"], bedforge::analysis::fit_power_law(levels).to_json());
  const std::string summary = r.stages["case"]["summary"].get<std::string>();
  EXPECT_NE(summary.find("convergence: levels 1-3"), std::string::npos) << summary;
  EXPECT_NE(summary.find(study["least_squares"]["explanation"].get<std::string>()), std::string::npos) << summary;
  EXPECT_TRUE(fs::exists(dir / "convergence/level_3/Allrun"));
  // Rerun unchanged: the study is part of the case, reused with it.
  const RunOutcome again = run(scene, dir);
  EXPECT_FALSE(again.built("case"));
  EXPECT_EQ(again.stages["case"]["convergence"], study);
}

// A study changed after it ran solves only what changed: the case (its finest level) stays, a
// level added is the only one solved, fewer levels or none drop what is left over, and another
// ratio solves the coarser levels again.
TEST(RunScene, AChangedStudySolvesOnlyTheLevelsThatChanged) {
  const fs::path dir = test_support::fresh_dir("study_reuse");
  auto study_scene = [](int levels, double ratio) {
    return small_scene("\"case\"",
                       fmt::format("[case]\nrun = true\n[case.convergence]\nlevels = {}\nratio = {}\n", levels, ratio),
                       kShrunk + "shrink_factor = 0.94\n[surface]\nedge_length_d = 0.1\n" + kPlainSurface);
  };
  const RunOutcome three = run(study_scene(3, 1.3), dir);
  const nlohmann::json& first = three.stages["case"]["convergence"];
  ASSERT_EQ(first["levels"].size(), 3u) << first.dump();
  const auto level_3_written = written(dir / "convergence/level_3/constant/polyMesh/owner");

  const RunOutcome four = run(study_scene(4, 1.3), dir);
  EXPECT_FALSE(four.built("case")) << four.printed;
  const nlohmann::json& more = four.stages["case"]["convergence"];
  ASSERT_EQ(more["levels"].size(), 4u) << more.dump();
  for (int k = 1; k < 3; ++k) {
    EXPECT_TRUE(more["levels"][k].value("reused", false)) << four.printed;
    EXPECT_EQ(more["levels"][k]["pressure_gradient_bed_pa_m"], first["levels"][k]["pressure_gradient_bed_pa_m"]);
  }
  EXPECT_FALSE(more["levels"][3].value("reused", false)) << four.printed;
  EXPECT_NE(four.printed.find("level 4 of 4, cells of"), std::string::npos) << four.printed;
  EXPECT_EQ(written(dir / "convergence/level_3/constant/polyMesh/owner"), level_3_written);
  EXPECT_TRUE(more.contains("least_squares"));  // four levels: the fit over all of them

  const RunOutcome back = run(study_scene(3, 1.3), dir);
  EXPECT_EQ(back.printed.find("cells of"), std::string::npos) << back.printed;  // nothing solved
  EXPECT_EQ(back.stages["case"]["convergence"]["conclusion"], first["conclusion"]);
  EXPECT_EQ(back.stages["case"]["summary"], three.stages["case"]["summary"]);
  EXPECT_FALSE(fs::exists(dir / "convergence/level_4"));
  // Unchanged, the study is reused with its case, and the bed (no bed.csv here) is not packed again.
  const RunOutcome same = run(study_scene(3, 1.3), dir);
  EXPECT_FALSE(same.built("pack")) << same.printed;
  EXPECT_EQ(same.stages["case"]["convergence"], back.stages["case"]["convergence"]);

  const RunOutcome none = run(study_scene(0, 1.3), dir);
  EXPECT_FALSE(none.stages["case"].contains("convergence"));
  const std::string summary = three.stages["case"]["summary"].get<std::string>();
  EXPECT_EQ(none.stages["case"]["summary"], summary.substr(0, summary.find("; convergence: ")));
  EXPECT_FALSE(fs::exists(dir / "convergence"));

  // The case kept no study, so asking for one again solves the case with it; then another ratio
  // keeps that case and solves the coarser levels anew.
  const RunOutcome again = run(study_scene(3, 1.3), dir, true);
  EXPECT_TRUE(again.built("case")) << again.printed;
  const RunOutcome wider = run(study_scene(3, 1.4), dir);
  EXPECT_FALSE(wider.built("case")) << wider.printed;
  for (int k = 1; k < 3; ++k) EXPECT_FALSE(wider.stages["case"]["convergence"]["levels"][k].value("reused", false));
  EXPECT_NE(wider.printed.find("level 3 of 3, cells of"), std::string::npos) << wider.printed;
}

// A study whose levels all fail (here the solver is stopped after 2 iterations) says so, level by
// level, and concludes nothing.
TEST(RunScene, AConvergenceStudyReportsTheLevelsThatFailed) {
  const fs::path dir = test_support::fresh_dir("convergence_failed");
  const Scene scene = small_scene(
      "\"case\"", "[case]\nrun = true\niterations = 2\n[case.convergence]\nlevels = 3\nratio = 1.4\n", kOpenSurface);
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& study = r.stages["case"]["convergence"];
  EXPECT_FALSE(study["complete"].get<bool>());
  EXPECT_FALSE(study.contains("grid_convergence"));
  for (const auto& level : study["levels"]) {
    EXPECT_NE(level.value("failure", "").find("did not converge"), std::string::npos) << level.dump();
    EXPECT_FALSE(level.contains("own_time_s")) << level.dump();  // no value, so no cost of one
  }
  EXPECT_NE(study["conclusion"].get<std::string>().find("no three successive levels"), std::string::npos);
  // The answer prints no number that was not computed: the finest value as such, no estimate.
  const nlohmann::json& answer = r.stages["case"]["answer"];
  EXPECT_FALSE(answer.contains("best_estimate_pa_m")) << answer.dump(1);
  EXPECT_FALSE(answer.contains("band_pa_m")) << answer.dump(1);
  EXPECT_NE(r.printed.find("no error band, so no best estimate"), std::string::npos) << r.printed;
  EXPECT_NE(r.printed.find("NOT converged"), std::string::npos) << r.printed;
  EXPECT_TRUE(fs::exists(dir / "pressure_drop.svg"));
}

TEST(RunScene, AConvergenceRequestThatCannotWorkIsRefusedByKey) {
  auto refused = [](const std::string& extra, const std::string& key) {
    try {
      small_scene("\"case\"", extra);
      ADD_FAILURE() << "accepted: " << extra;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused("[case]\nrun = true\n[case.convergence]\nlevels = 2\n", "case.convergence.levels");
  refused("[case]\nrun = true\n[case.convergence]\nlevels = 3\nratio = 1.05\n", "case.convergence.ratio");
  refused("[case.convergence]\nlevels = 3\n", "case.run = true");
  refused("[case]\nrun = true\n[case.convergence]\nlevels = 3\nrefine = 2\n", "case.convergence.refine");
}

// The shipped box example (the other scenes that make a case have tests in
// tests/cases/test_openfoam_case.cpp): meshed and written by the pipeline, checked by OpenFOAM's
// checkMesh; its solve is left to the benchmark.
TEST(RunScene, TheBoxExampleGivesACaseCheckMeshPasses) {
  const Scene scene = example_scene("box_bed_flow.toml", {{"case.run", false}});
  const fs::path dir = test_support::fresh_dir("box_example");
  run_scene(scene, dir, {run_wants(scene), false, false}, {false, true});
  const std::string log = (dir / "checkMesh.log").string();
  const std::string command = "cd '" + (dir / "case").string() +
                              "' && WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam} checkMesh > '" + log + "' 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0);
  std::ifstream check(log);
  std::stringstream out;
  out << check.rdbuf();
  EXPECT_NE(out.str().find("Mesh OK."), std::string::npos) << out.str();
}

// Verification of the whole route on a case with an exact answer: the shipped empty tube as
// shipped (three levels from a 0.2 d surface edge, ratio 1.3, the default polyhedral cells)
// against Hagen-Poiseuille, 32 mu u / D^2. The bound on the finest level is the 1 % the
// verification must reach (issue 24); the coarser levels' bound is the largest error measured
// over the benchmark's levels of this size and coarser (docs/mesh_case_benchmark.md).
TEST(RunScene, TheEmptyTubeExampleMatchesHagenPoiseuille) {
  const Scene scene = example_scene("empty_tube_verification.toml");
  const fs::path dir = test_support::fresh_dir("empty_tube");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  const double mu = 1.0e-3, d = 0.003, u = 1.0 * mu / (1000.0 * d), diameter = 2.0 * d;
  const double exact = 32.0 * mu * u / (diameter * diameter);
  EXPECT_NEAR(c["exact_pressure_gradient_pa_m"].get<double>(), exact, 1e-12 * exact);
  const nlohmann::json& study = c["convergence"];
  ASSERT_EQ(study["levels"].size(), 3u) << study.dump();
  EXPECT_NEAR(study["exact_pa_m"].get<double>(), exact, 1e-12 * exact);
  for (const auto& level : study["levels"]) {
    ASSERT_FALSE(level.contains("failure")) << level.dump();
    const double error = level["pressure_gradient_bed_pa_m"].get<double>() / exact - 1.0;
    EXPECT_NEAR(level["relative_error_to_exact"].get<double>(), error, 1e-12);
    EXPECT_LT(std::abs(error), level["level"] == 1 ? 0.01 : kCoarseTubeError) << level.dump();
    // Momentum: the wall's drag is the push through inlet and outlet, but for the momentum flux
    // from plug to parabola (-0.32 %) and the forces object's wall gradient, whose error grows on
    // coarser cells: measured (2026-11-26) -1.5 % at 5 k cells, -1.5 % at 2 k, -1.8 and -2.1 %
    // at 1 k. Hence 2 % on the finest, 3 % on the others.
    EXPECT_LT(std::abs(level["drag"]["force_balance_relative_error"].get<double>()), level["level"] == 1 ? 0.02 : 0.03)
        << level.dump();
    EXPECT_EQ(level["drag"]["wall_share"].get<double>(), 1.0);  // no particles: no other drag
  }
  EXPECT_FALSE(c["flow"].contains("eisfeld_schnitzlein_pa_m"));  // no correlation for an empty tube
  EXPECT_NE(study["conclusion"].get<std::string>().find("against the exact"), std::string::npos);
}

// Verification around spheres: the shipped simple cubic column (Stokes flow, solid fraction
// 0.216) from a 0.1 d surface edge, half the example's, so that it runs in seconds, against Zick &
// Homsy's drag. On such meshes the levels lie 8-19 % under it, their errors falling at order 1.7
// (measured 2026-11-27; from 0.05 d: 4-11 %, order 2.0, the extrapolation +0.8 %). The order's
// bounds are the 1-3 the study's order must lie in (issue 24).
namespace {

// Zick & Homsy's (1982) gradient (Pa/m) through a simple cubic array at solid fraction `phi`,
// their drag K there, for the examples' spheres (d = 3 mm, water, Re_p = 0.01): 6 pi mu a K U / L^3
// with L = d (pi / (6 phi))^(1/3).
double zick_homsy_gradient(double phi, double K) {
  const double pi = std::acos(-1.0), mu = 1.0e-3, d = 0.003, u = 0.01 * mu / (1000.0 * d);
  const double side = d * std::cbrt(pi / (6.0 * phi));
  return 3.0 * pi * mu * d * K * u / std::pow(side, 3);
}

// A simple cubic array's case (phi = 0.216) against Zick & Homsy (K = 7.442): its three levels
// each below it and nearer than the coarser one, at an order between 1 and 3; or, given
// `finest_error`, the finest level's error there instead of the order.
void expect_converging_to_zick_homsy(const nlohmann::json& c, double* finest_error = nullptr) {
  const double exact = zick_homsy_gradient(0.216, 7.442);
  ASSERT_TRUE(c["exact_pressure_gradient_pa_m"].is_number()) << c.dump();
  EXPECT_NEAR(c["exact_pressure_gradient_pa_m"].get<double>(), exact, 1e-9 * exact);
  const nlohmann::json& study = c["convergence"];
  ASSERT_EQ(study["levels"].size(), 3u) << study.dump();
  double coarser_error = -1.0;  // the errors, coarsest first, each nearer zero than the last
  for (auto level = study["levels"].rbegin(); level != study["levels"].rend(); ++level) {
    ASSERT_FALSE(level->contains("failure")) << level->dump();
    const double error = (*level)["relative_error_to_exact"].get<double>();
    EXPECT_LT(error, 0.0) << level->dump();
    EXPECT_GT(error, coarser_error) << level->dump();
    coarser_error = error;
  }
  if (finest_error) {
    *finest_error = coarser_error;
    return;
  }
  ASSERT_TRUE(study["order_from_exact"].is_number()) << study.dump();
  EXPECT_GT(study["order_from_exact"].get<double>(), 1.0);
  EXPECT_LT(study["order_from_exact"].get<double>(), 3.0);
}

}  // namespace

TEST(RunScene, TheSimpleCubicExampleConvergesToZickAndHomsy) {
  const Scene scene = example_scene("simple_cubic_verification.toml", {{"surface.edge_length_d", 0.1},
                                                                       {"surface.contact_edge_length_d", 0.05}});
  const fs::path dir = test_support::fresh_dir("simple_cubic");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  expect_converging_to_zick_homsy(c);
  std::ifstream velocity(dir / "case/0/U");
  std::stringstream text;
  text << velocity.rdbuf();
  EXPECT_NE(text.str().find("type            slip;"), std::string::npos);  // the box's sides
  EXPECT_FALSE(c["flow"].contains("eisfeld_schnitzlein_pa_m"));  // the known answer instead
}

// A treatment that changes the spheres changes the array: shrink (every sphere scaled by 0.99,
// contacts or not) leaves no known answer; the untreated array's bounds it from above (solid
// taken), the bed's reference (cases::KnownBound), the correlation beside it.
TEST(RunScene, ASimpleCubicColumnWhoseSpheresAreShrunkIsBoundedByTheUntreatedArray) {
  const Scene scene = example_scene("simple_cubic_verification.toml",
                                    {{"surface.edge_length_d", 0.15}, {"surface.contact_edge_length_d", 0.075},
                                     {"contacts.treatment", std::string("shrink")}, {"case.convergence.levels", 0LL}});
  const fs::path dir = test_support::fresh_dir("simple_cubic_shrunk");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  EXPECT_TRUE(c["exact_pressure_gradient_pa_m"].is_null()) << c.dump();
  EXPECT_TRUE(c["flow"].contains("eisfeld_schnitzlein_pa_m"));
  const double untreated = zick_homsy_gradient(0.216, 7.442);
  ASSERT_TRUE(c["flow"]["bound"].is_object()) << c["flow"].dump();
  EXPECT_NEAR(c["flow"]["bound"]["pa_m"].get<double>(), untreated, 1e-9 * untreated);
  EXPECT_EQ(c["flow"]["bound"]["side"], "above");
  EXPECT_NEAR(c["flow"]["ratio_to_bound"].get<double>(),
              c["flow"]["pressure_gradient_bed_pa_m"].get<double>() / untreated, 1e-12);
}

// The touching array with its contacts bridged (scenes/examples/touching_cubic_bridged.toml), one
// coarse mesh: no exact answer, the untreated touching array's (Zick & Homsy 1982, Table 2, K =
// 42.1 at pi / 6) its bound from below, the answer's reference.
TEST(RunScene, TheBridgedTouchingExampleIsBoundedFromBelowByTheUntreatedArray) {
  const Scene scene = example_scene("touching_cubic_bridged.toml", {{"surface.edge_length_d", 0.15},
                                                                    {"surface.contact_edge_length_d", 0.075},
                                                                    {"case.convergence.levels", 0LL}});
  const fs::path dir = test_support::fresh_dir("touching_bridged");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  const double untreated = zick_homsy_gradient(std::acos(-1.0) / 6.0, 42.1);
  EXPECT_TRUE(c["exact_pressure_gradient_pa_m"].is_null()) << c.dump();
  ASSERT_TRUE(c["flow"]["bound"].is_object()) << c["flow"].dump();
  EXPECT_NEAR(c["flow"]["bound"]["pa_m"].get<double>(), untreated, 1e-9 * untreated);
  EXPECT_EQ(c["flow"]["bound"]["side"], "below");
  EXPECT_EQ(c["answer"]["reference"]["bound"], "below");
  EXPECT_NEAR(c["answer"]["reference"]["pa_m"].get<double>(), untreated, 1e-9 * untreated);
}

// Issue 57's layered route as shipped (scenes/examples/layered_bed_accuracy.toml), one coarse mesh:
// its particles carry prism stacks, the solve is on the tetrahedra and prisms themselves, and the
// drag on walls and particles balances the push through inlet and outlet. Not to the 2 % of the
// meshes without layers (OpenFoamCase.SmallBedPressureDropAgreesWithEisfeldSchnitzlein): on
// layered meshes the forces read the particles' pressure drag high, by +1.4 to +3.8 % of the push
// on the 40- and 500-sphere beds' levels and +2.9 % on this mesh (docs/mesh_case_benchmark.json at
// f96000c), traced on one case to the vertex-fitted pressure gradient (docs/findings.md, 2026-12-07,
// session 92); the 5 % still catches a patch left out or a sign, which miss by far more (the
// particles carry about 90 %).
TEST(RunScene, TheLayeredExampleSolvesOnItsPrismsAndBalancesItsDrag) {
  const Scene scene = example_scene("layered_bed_accuracy.toml", {{"surface.edge_length_d", 0.3},
                                                                  {"surface.contact_edge_length_d", 0.1},
                                                                  {"case.convergence.levels", 0LL}});
  const fs::path dir = test_support::fresh_dir("layered_example");
  const RunOutcome r = run(scene, dir);
  ASSERT_TRUE(r.stages["mesh"].contains("layers")) << r.stages["mesh"].dump();
  const nlohmann::json& layers = r.stages["mesh"]["layers"];
  EXPECT_GT(layers["cells"]["prisms"].get<long>(), 0) << layers.dump();
  EXPECT_GT(layers["stacks_at_full_thickness"].get<long>(), 0) << layers.dump();
  const nlohmann::json& flow = r.stages["case"]["flow"];
  EXPECT_EQ(flow["mesh"]["mesher"], "gmsh tetrahedra");
  EXPECT_TRUE(flow["converged"].get<bool>()) << flow.dump();
  EXPECT_LT(std::abs(flow["drag"]["force_balance_relative_error"].get<double>()), 0.05) << flow["drag"].dump();
}

// The same array as a periodic section (scenes/examples/periodic_cubic_verification.toml: three
// cells, cyclic inlet and outlet, meanVelocityForce; order 2.05 measured at the example's
// settings, 2026-11-28). Its solve stops only once the driving gradient has settled: over the
// last block of iterations it moves by less than a tenth of Zick & Homsy's 0.1 % (at the
// general targets of 1e-4 it still moved by 2.3e-4 on this mesh, 2026-12-07).
TEST(RunScene, ThePeriodicCubicExampleConvergesToZickAndHomsy) {
  const Scene scene = example_scene("periodic_cubic_verification.toml", {{"surface.edge_length_d", 0.1},
                                                                         {"surface.contact_edge_length_d", 0.05}});
  const fs::path dir = test_support::fresh_dir("periodic_cubic");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  EXPECT_TRUE(c["periodic_mean_velocity_m_s"].is_number());
  EXPECT_LT(c["flow"]["pressure_gradient_change_last_block"].get<double>(), 1e-4) << c["parameters"].dump();
  // Each level's iteration error reaches the answer, and at these targets is below 1e-4 (-1e-5
  // on 38 k polyhedra of this array, docs/findings.md, session 95): estimated, or if its changes
  // did not shrink, moved by less than that over its last block.
  const nlohmann::json& iteration = c["answer"]["iteration_errors"];
  ASSERT_EQ(iteration.size(), 3u) << c["answer"].dump();
  for (const nlohmann::json& level : iteration) {
    const nlohmann::json& e = level["estimate"];
    EXPECT_LT(std::abs(e["geometric"].get<bool>() ? e["remaining"].get<double>() : e["last_change"].get<double>()), 1e-4)
        << level.dump();
  }
  expect_converging_to_zick_homsy(c);
}

// The same array whole in a box periodic on every side (scenes/examples/
// periodic_box_cubic_verification.toml: 27 spheres, three cyclic pairs): checkMesh matches each
// pair's points and finds the mesh OK, and the three levels fall towards Zick & Homsy's drag as
// the cells refine. On these polyhedra the finest level read -13.5 and -13.6 % and the study's
// order 0.95 and 1.07 (two runs, 2026-12-04; gmsh's meshes differ between runs), so the order is
// not asserted here and the finest error is bounded by 16 %, above both. Solved to the general
// residual targets of 1e-4, as those runs were: the periodic default of 1e-6 takes about twice the
// iterations (2.3 times on a 65 k array, 2026-12-07) and moves dp/L by tenths of a per cent (the
// test above checks it).
TEST(RunScene, ABoxPeriodicOnEverySideConvergesToZickAndHomsy) {
  const fs::path dir = test_support::fresh_dir("periodic_box_cubic");
  const RunOutcome r = run(example_scene("periodic_box_cubic_verification.toml",
                                         {{"case.residual_u", 1e-4}, {"case.residual_p", 1e-4}}),
                           dir);
  double finest_error = -1.0;
  expect_converging_to_zick_homsy(r.stages["case"], &finest_error);
  EXPECT_GT(finest_error, -0.16) << r.stages["case"]["convergence"].dump();
  std::stringstream boundary, check;
  boundary << std::ifstream(dir / "case/constant/polyMesh/boundary").rdbuf();
  for (const char* neighbour : {"x_max", "y_max", "outlet"})
    EXPECT_NE(boundary.str().find(fmt::format("neighbourPatch  {};", neighbour)), std::string::npos) << neighbour;
  check << std::ifstream(dir / "case/log.checkMesh").rdbuf();
  EXPECT_NE(check.str().find("Coupled point location match"), std::string::npos) << check.str();
  EXPECT_NE(check.str().find("Mesh OK."), std::string::npos) << check.str();
}

// The random array (scenes/examples/random_array_stokes.toml, seed 1) on one coarser mesh: the
// cyclic case converges and passes checkMesh, and is compared with van der Hoef et al. at the
// solid fraction of the spheres as solved (as packed, shrunk by 0.99). On one mesh of surface
// edge 0.15 d, dp/L read 0.889, 0.728 and 0.880 of vdH for seeds 1-3 (2026-12-04; the finest of
// the three-level studies 0.74-0.91, their extrapolations 0.90-1.16): the bounds 0.8 and 1.0 lie
// 0.09 and 0.11 from seed 1's value, within the seeds' spread of 0.16. vdH's gradient without the
// 1 / (1 - phi) of its drag would put the ratio at 1.45; the fraction is checked on its own.
// Solved, as those runs were, to the general residual targets of 1e-4 (the periodic default of
// 1e-6 moves dp/L by tenths of a per cent, far inside the bounds, for about twice the iterations).
TEST(RunScene, TheRandomArrayExampleIsComparedWithVanDerHoef) {
  const Scene scene = example_scene("random_array_stokes.toml", {{"surface.edge_length_d", 0.15},
                                                                 {"surface.contact_edge_length_d", 0.06},
                                                                 {"case.convergence.levels", 0LL},
                                                                 {"case.residual_u", 1e-4},
                                                                 {"case.residual_p", 1e-4}});
  const fs::path dir = test_support::fresh_dir("random_array");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& c = r.stages["case"];
  EXPECT_TRUE(c["flow"]["converged"].get<bool>()) << c["flow"].dump();
  ASSERT_TRUE(c["stokes_array"].is_object()) << c.dump();
  const double packed = 1.0 - c["section"]["void_fraction_bed"].get<double>();
  EXPECT_NEAR(c["stokes_array"]["solid_fraction"].get<double>(), packed * std::pow(0.99, 3), 1e-12);
  const double ratio = c["flow"]["ratio_to_van_der_hoef"].get<double>();
  EXPECT_GT(ratio, 0.8);
  EXPECT_LT(ratio, 1.0);
  std::stringstream check;
  check << std::ifstream(dir / "case/log.checkMesh").rdbuf();
  EXPECT_NE(check.str().find("Coupled point location match"), std::string::npos) << check.str();
  EXPECT_NE(check.str().find("Mesh OK."), std::string::npos) << check.str();
}

// On gmsh's tetrahedra the pressure's cell-to-cell noise, read by gradients from the four face
// neighbours, drove the same tube's pressure drop +12 to +17 % above the exact one on 5 k to 160 k
// tetrahedra (measured 2026-11-24; +15.9 % on this mesh, 2026-12-03); fitted over the cells that
// share a vertex and with the full non-orthogonal correction it settled 1.3-2.1 % low at every
// size (2026-12-03 and 2026-12-04); with H/A's flux taken at the faces' centres it reads -0.08 to
// +0.56 % on 7.5 k to 452 k tetrahedra (2026-12-04: docs/findings.md, and the generated
// Verification of docs/mesh_case_benchmark.md), +0.14 % on this mesh, where the faceted section
// alone reads +0.2 to +1.3 % high. The bound, 1 %, is under the old bias's smallest measured
// value and above the new one's largest.
TEST(RunScene, OnTetrahedraTheEmptyTubeIsWithinOnePerCentOfHagenPoiseuille) {
  const Scene scene = example_scene("empty_tube_verification.toml",
                                    {{"case.cells", std::string("tetrahedra")}, {"case.convergence.levels", 0LL}});
  const fs::path dir = test_support::fresh_dir("empty_tube_tetrahedra");
  const RunOutcome r = run(scene, dir);
  const nlohmann::json& flow = r.stages["case"]["flow"];
  EXPECT_EQ(flow["mesh"]["mesher"], "gmsh tetrahedra");
  EXPECT_EQ(flow["mesh"]["cells"], r.stages["case"]["cells"]);
  EXPECT_LT(std::abs(flow["relative_error_to_exact"].get<double>()), 0.01) << flow.dump();
}

// The mesh's estimate from the scene alone: for the empty tube its fluid volume is exact, and
// its cells fall below what gmsh makes (the estimate errs low, so a refusal is never wrong).
TEST(RunScene, TheMeshEstimateOfTheEmptyTubeIsExactInVolumeAndLowInCells) {
  const Scene scene = example_scene("empty_tube_verification.toml", {{"case.convergence.levels", 0LL}});
  const double pi = std::acos(-1.0), exact_volume = pi * 0.003 * 0.003 * 0.036;
  const MeshEstimate e = estimate_mesh(scene);
  EXPECT_NEAR(e.fluid_volume_m3, exact_volume, 1e-12 * exact_volume);
  const fs::path dir = test_support::fresh_dir("empty_tube_estimate");
  const RunOutcome r = run(scene, dir);
  EXPECT_LT(e.cells, r.stages["mesh"]["cells"].get<double>());
}

// A mesh that cannot fit is refused before packing, naming the key and the edge that would fit:
// a million spheres at 0.05 d need far more than any machine here (and nothing is written).
TEST(RunScene, AMeshBeyondMemoryIsRefusedBeforePacking) {
  const Scene scene = read_scene(parse_scene_text("[container]\ndiameter_d = 40\n[particles]\ncount = 1000000\n"
                                                  "[surface]\nedge_length_d = 0.05\n[outputs]\nfiles = [\"mesh\"]\n",
                                                  "huge.toml"),
                                 "huge.toml");
  EXPECT_GT(estimate_mesh(scene).peak_bytes, 1e12);
  const fs::path dir = test_support::fresh_dir("mesh_beyond_memory");
  try {
    run_scene(scene, dir, {run_wants(scene), false, false}, {false, false});
    FAIL() << "a mesh of " << estimate_mesh(scene).cells << " cells was not refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("surface.edge_length_d = 0.05"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("allowed: surface.edge_length_d >="), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "bed.csv"));
  // The same test against a given memory: a small bed fits in 1 GB and not in 1 MB.
  const Scene small = small_scene("\"mesh\"");
  EXPECT_NO_THROW(refuse_mesh_beyond_memory(small, 1e9));
  EXPECT_THROW(refuse_mesh_beyond_memory(small, 1e6), InputError);
}

// A case that is run peaks in simpleFoam, whose two processes held together 897 and 1038 bytes
// per tetrahedron on the dual (2026-11-28) and about 3.4 kB on the tetrahedra (2026-12-04;
// docs/findings.md), above the mesh stage's 460: a memory that fits the mesh alone is refused for
// the run, naming the way out, and the tetrahedra need more.
TEST(RunScene, ACaseThatIsRunIsRefusedWhenTheSolverWouldNotFit) {
  const Scene written = small_scene("\"case\"", "[case]\nrun = false\n");
  const Scene run = small_scene("\"case\"", "[case]\nrun = true\n");
  const Scene run_tetrahedra = small_scene("\"case\"", "[case]\nrun = true\ncells = \"tetrahedra\"\n");
  const MeshEstimate w = estimate_mesh(written), r = estimate_mesh(run), t = estimate_mesh(run_tetrahedra);
  EXPECT_EQ(w.cells, r.cells);
  EXPECT_FALSE(w.peak_in_solver);
  EXPECT_TRUE(r.peak_in_solver);
  EXPECT_TRUE(t.peak_in_solver);
  EXPECT_GT(t.peak_bytes, r.peak_bytes);
  const double available = 0.5 * (w.peak_bytes + r.peak_bytes);
  EXPECT_NO_THROW(refuse_mesh_beyond_memory(written, available));
  try {
    refuse_mesh_beyond_memory(run, available);
    FAIL() << "simpleFoam's " << r.peak_bytes << " bytes were not refused in " << available;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("in simpleFoam's processes together"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("case.run = false"), std::string::npos) << e.what();
  }
}

// Bridged contacts, their gaps refined to 4 cells down to a contact edge of 0.02 d.
const std::string kRefinedGaps =
    "[contacts]\ntreatment = \"bridge\"\n[surface]\nedge_length_d = 0.1\ncontact_edge_length_d = 0.02\n"
    "cells_per_gap = 4\n";

// Once packed, the estimate counts the cells cells_per_gap puts in the bed's narrow gaps, which
// the scene alone cannot foresee: with memory a little short of the packed bed's estimate, the
// scene passes before packing and is refused after it, naming cells_per_gap and what would fit.
TEST(RunScene, AMeshWhoseGapsDoNotFitIsRefusedBeforeItsSurface) {
  const Scene scene = small_scene("\"mesh\"", "", kRefinedGaps);
  const Bed bed = pack_stage(scene, {false, false}).bed;
  const MeshEstimate before = estimate_mesh(scene), after = estimate_mesh(scene, bed);
  ASSERT_GT(after.gap_cells, 0.5 * after.cells);
  const double available = 0.9 * after.peak_bytes;
  ASSERT_LT(before.peak_bytes, available);
  EXPECT_NO_THROW(refuse_mesh_beyond_memory(scene, available));
  try {
    refuse_mesh_beyond_memory(scene, bed, available);
    FAIL() << "a mesh of " << after.cells << " cells was not refused in " << available << " bytes";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("surface.cells_per_gap = 4 with surface.contact_edge_length_d = 0.02"),
              std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("allowed: surface.cells_per_gap <= about"), std::string::npos) << e.what();
  }
}

// The estimate with its gaps errs low, and not by much: gmsh made 1.03-1.39 times its cells in
// nine runs with cells_per_gap 3-8 (docs/findings.md, 2026-11-27; this scene 1.13); the bound
// leaves room for gmsh's meshes differing between builds.
TEST(RunScene, TheMeshEstimateWithGapsIsLowButNear) {
  const Scene scene = small_scene("\"mesh\"", "", kRefinedGaps);
  const fs::path dir = test_support::fresh_dir("estimate_with_gaps");
  const RunOutcome r = run(scene, dir);
  const double cells = r.stages["mesh"]["cells"].get<double>();
  const double estimate = r.stages["mesh"]["estimate"]["cells"].get<double>();
  EXPECT_GT(r.stages["mesh"]["estimate"]["gap_cells"].get<double>(), 0.5 * estimate);
  EXPECT_GT(cells, estimate);
  EXPECT_LT(cells, 1.6 * estimate);
}

const std::string kBridgedForty =
    "[container]\ndiameter_d = 4\n[particles]\ncount = 40\ndiameter_m = 0.003\n[contacts]\ntreatment = \"bridge\"\n"
    "[surface]\nedge_length_d = 0.15\ncontact_edge_length_d = 0.05\ncells_per_gap = 0\n[mesh]\nthreads = 1\n"
    "[outputs]\nfiles = [\"mesh\"]\n";

// Without cells_per_gap the estimate counts the cells graded around contacts: per edge of a
// treated contact's loop (kCellsPerContactLoopEdge, calibrated on a = 14, N = 1e4) and per
// contact left as a thin gap (kCellsPerThinGapContact, calibrated on a = 5, N = 500, shrink).
// gmsh made 1.02-1.36 times the estimate in fifteen runs on five beds, 0.1-0.2 d
// (docs/findings.md, 2026-12-01); this bed (a = 4, N = 40, 0.15 d) 1.12 bridged and 1.10 shrunk,
// and 1.66 and 1.21 times the estimate without the contacts' terms. 1.4 leaves room for gmsh's
// meshes differing between builds and fails the bridged estimate without its term; the shrunk
// one's term is checked by its count.
TEST(RunScene, TheMeshEstimateAtContactsIsLowButNear) {
  for (const std::string treatment : {"bridge", "shrink"}) {
    std::string text = kBridgedForty;
    text.replace(text.find("\"bridge\""), 8, "\"" + treatment + "\"");
    const fs::path dir = test_support::fresh_dir("estimate_at_contacts_" + treatment);
    const RunOutcome r = run(read_scene(parse_scene_text(text, "t.toml"), "t.toml"), dir);
    const double cells = r.stages["mesh"]["cells"].get<double>();
    const double estimate = r.stages["mesh"]["estimate"]["cells"].get<double>();
    ASSERT_GT(r.stages["mesh"]["estimate"]["contact_cells"].get<double>(), 0.0) << treatment;
    EXPECT_GT(cells, estimate) << treatment;
    EXPECT_LT(cells, 1.4 * estimate) << treatment;
  }
}

// Cells graded around contacts do not fall with the surface edge as the bulk's do: a mesh that
// does not fit for them names the contact edge too.
TEST(RunScene, AMeshWhoseContactsDoNotFitNamesTheContactEdge) {
  const Scene scene = read_scene(parse_scene_text(kBridgedForty, "t.toml"), "t.toml");
  const Bed bed = pack_stage(scene, {false, false}).bed;
  const MeshEstimate e = estimate_mesh(scene, bed);
  ASSERT_GT(e.contact_cells, 0.0);
  try {
    refuse_mesh_beyond_memory(scene, bed, 0.5 * e.peak_bytes);
    FAIL() << "a mesh of " << e.cells << " cells was not refused in half its memory";
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("million of them around its contacts"), std::string::npos) << what;
    EXPECT_NE(what.find("a longer surface.contact_edge_length_d (now 0.05)"), std::string::npos) << what;
  }
}

// A target void fraction sets a periodic section's period from the spheres drawn (a normal size
// distribution, so not from the scene's mean): the analysis, which integrates each sphere and
// its image across the period, measures the target; the bed read back for a later stage keeps
// the spheres' period, not the scene's estimate.
TEST(RunScene, ATargetVoidFractionIsTheSectionsVoidFraction) {
  const std::string text =
      "[container]\ndiameter_d = 4\n[particles]\ncount = 150\ndistribution = \"normal\"\nmean_m = 0.002\n"
      "std_m = 0.0002\n[packing.soft_sphere]\ntarget_void_fraction = 0.45\n[outputs]\nfiles = [";
  const fs::path dir = test_support::fresh_dir("target_void_fraction");
  const RunOutcome packed = run(read_scene(parse_scene_text(text + "\"positions\"]\n", "t.toml"), "t.toml"), dir);
  EXPECT_NEAR(packed.stages["pack"]["void_fraction"]["whole_bed"].get<double>(), 0.45, 1e-9);
  const RunOutcome analysed =
      run(read_scene(parse_scene_text(text + "\"positions\", \"analysis\"]\n", "t.toml"), "t.toml"), dir);
  ASSERT_FALSE(analysed.built("pack"));
  EXPECT_NEAR(analysed.stages["analysis"]["void_fraction"]["whole_bed"].get<double>(), 0.45, 1e-9);
}

// A periodic section of the empty tube has fully developed flow in every cell, so the cyclic
// case driven by meanVelocityForce must give Hagen-Poiseuille: measured -0.016 % and -0.011 % on
// meshes of 900-1400 cells (2026-11-28); 1 % leaves room for gmsh's meshes differing between
// builds. A wrong drive (the superficial velocity held as the mean, a flow rate not scaled) or a
// cyclic pair mismatched is off by more. On two processes, whose decomposition must keep the
// cyclic pair's faces together (else the flow rate over the outlet has no faces and the run stops).
TEST(RunScene, APeriodicEmptyTubeGivesHagenPoiseuille) {
  const std::string text =
      "[container]\ndiameter_d = 3\nperiod_z_d = 3\n[particles]\ncount = 0\ndiameter_m = 0.002\n"
      "[surface]\nedge_length_d = 0.25\n[mesh]\nthreads = 1\n[case]\nrun = true\nprocessors = 2\n"
      "[case.convergence]\nlevels = 0\n"
      "[outputs]\nfiles = [\"case\"]\n";
  const fs::path dir = test_support::fresh_dir("periodic_empty_tube");
  const RunOutcome r = run(read_scene(parse_scene_text(text, "t.toml"), "t.toml"), dir);
  const nlohmann::json& flow = r.stages["case"]["flow"];
  EXPECT_TRUE(flow["converged"].get<bool>());
  EXPECT_LT(std::abs(flow["relative_error_to_exact"].get<double>()), 0.01) << flow.dump();
  std::ifstream boundary(dir / "case/constant/polyMesh/boundary");
  std::stringstream text_of;
  text_of << boundary.rdbuf();
  EXPECT_NE(text_of.str().find("neighbourPatch  outlet;"), std::string::npos);
}

// The shipped periodic section (scenes/examples/periodic_section_flow.toml: a = 5, 212 spheres,
// 10 d, bridges, those the periodic planes cross opened): OpenFOAM's checkMesh finds the cyclic
// pair's points where they should be and the mesh OK, and the flow converges.
TEST(RunScene, APeriodicSectionOfABedIsACyclicCase) {
  const fs::path dir = test_support::fresh_dir("periodic_section_case");
  const RunOutcome r = run(example_scene("periodic_section_flow.toml"), dir);
  EXPECT_GT(r.stages["surface"]["periodic_planes_m"]["contacts_opened"].get<long>(), 0);
  const nlohmann::json& flow = r.stages["case"]["flow"];
  EXPECT_TRUE(flow["converged"].get<bool>()) << flow.dump();
  EXPECT_GT(flow["pressure_gradient_bed_pa_m"].get<double>(), 0.0);
  std::ifstream log(dir / "case/log.checkMesh");
  std::stringstream check;
  check << log.rdbuf();
  EXPECT_NE(check.str().find("Coupled point location match"), std::string::npos) << check.str();
  EXPECT_NE(check.str().find("Mesh OK."), std::string::npos) << check.str();
}

namespace {

// A box section cut through at its periodic planes (a box 4 d square, period 4 d, 64 spheres of
// `seed`, contacts `treatment`, edge 0.15 d, 4 cells per gap): the surface stage's report.
nlohmann::json box_section_surface(const std::string& treatment, int seed) {
  const std::string text = fmt::format(
      "[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiod_z_d = 4\n[particles]\ncount = 64\n"
      "diameter_m = 0.003\n[packing]\nseed = {}\n[contacts]\ntreatment = \"{}\"\n"
      "at_periodic_planes = \"cut\"\n[surface]\nedge_length_d = 0.15\n[outputs]\nfiles = [\"positions\", \"stl\"]\n",
      seed, treatment);
  const fs::path dir = test_support::fresh_dir(fmt::format("box_section_{}_{}", treatment, seed));
  return run(read_scene(parse_scene_text(text, "box.toml"), "box.toml"), dir).stages["surface"];
}

}  // namespace

// Enlarged spheres in such a section: the surface passes the stage's gate (min angle 2 deg) on
// each of the three beds of docs/findings.md (2026-12-03, 2026-12-05), also where the plane
// passes just above a sphere's union with a side, its section 0.005-0.01 d from that side
// (seed 2: triangles of 1.26 deg there while the side's row at the plane kept the surface edge's
// spacing).
TEST(RunScene, EnlargedSpheresInABoxSectionAreCutThroughAtItsPlanes) {
  for (int seed : {1, 2, 3}) {
    const nlohmann::json s = box_section_surface("enlarge", seed);
    EXPECT_GE(s["min_angle_deg"].get<double>(), 2.0) << "seed " << seed;
    EXPECT_EQ(s["periodic_planes_m"]["contacts_opened"].get<long>(), 0) << "seed " << seed;
    EXPECT_GT(s["contacts_treated"]["particle_wall"].get<long>(), 0) << "seed " << seed;
  }
}

// Capped, seed 1: a cap's regular rings across the first seam clear of the spheres' centres and
// contacts (0.6 d below the planes) took other diagonals in the sphere's two copies, so the parts
// did not join there (docs/findings.md, 2026-12-05); the section is joined at the next seam clear.
TEST(RunScene, ABoxSectionWhoseSeamDoesNotJoinIsJoinedAtTheNextSeamClear) {
  const nlohmann::json s = box_section_surface("cap", 1);
  EXPECT_GT(s["periodic_planes_m"]["seam_depth_d"].get<double>(), 0.6 + 2 * 0.15);
  EXPECT_EQ(s["check"]["closed"], true) << s["check"].dump();
}
