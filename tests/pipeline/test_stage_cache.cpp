// Which stages a run reuses and which it builds, decided from the earlier report and the files
// in the directory, without running anything.
#include "pipeline/stage_cache.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

using namespace bedforge::pipeline;

namespace {

const StageKeys kKeys{"pack-key", "analysis-key", "surface-key", "mesh-key", "case-key", "study-key"};

// The report a complete earlier run with these keys leaves.
nlohmann::json complete_report(const StageKeys& k = kKeys) {
  auto stage = [](const std::string& key) { return nlohmann::json{{"cache_key", key}, {"summary", "x"}, {"time_s", 1.0}}; };
  nlohmann::json r;
  r["stages"]["pack"] = stage(k.pack);
  r["stages"]["analysis"] = stage(k.analysis);
  r["stages"]["analysis"]["files"] = {"radial_profile.csv", "contacts.csv"};
  r["stages"]["surface"] = stage(k.surface);
  r["stages"]["mesh"] = stage(k.mesh);
  r["stages"]["case"] = stage(k.case_);
  return r;
}

// A directory holding `files`.
struct Directory {
  std::set<std::string> files;
  bool operator()(const std::string& f) const { return files.count(f) > 0; }
};

const Directory kEverything{{"bed.csv", "bed.vtp", "radial_profile.csv", "contacts.csv", "fluid.stl", "bed.stl",
                             "fluid.vtp", "fluid.msh", "case/Allrun"}};

// The default scene's outputs: the bed, its analysis and the case, no mesh or surface files.
const Wants kDefault{true, true, true, false, false, true};

int built(const RunPlan& p) {
  return p.pack.build + p.analysis.build + p.surface.build + p.mesh.build + p.case_.build;
}

}  // namespace

TEST(StageCache, AFirstRunBuildsEveryStageItNeeds) {
  const RunPlan p = plan_run(kDefault, kKeys, nullptr, Directory{});
  EXPECT_TRUE(p.pack.build && p.analysis.build && p.surface.build && p.mesh.build && p.case_.build);
  EXPECT_TRUE(p.write_bed_csv && p.write_bed_vtp);
  EXPECT_FALSE(p.load_bed || p.load_mesh);
  // A bed alone needs nothing downstream.
  const RunPlan bed = plan_run({true, false, false, false, false, false}, kKeys, nullptr, Directory{});
  EXPECT_EQ(built(bed), 1);
  EXPECT_FALSE(bed.surface.involved || bed.mesh.involved || bed.case_.involved);
}

TEST(StageCache, AnUnchangedRerunBuildsNothingWhateverItsOutputs) {
  // The default scene writes no fluid.msh: the case is reused from its own key, and nothing
  // under it is built or even read back.
  const RunPlan p = plan_run(kDefault, kKeys, complete_report(), kEverything);
  EXPECT_EQ(built(p), 0);
  EXPECT_FALSE(p.load_bed || p.load_mesh || p.write_bed_csv || p.write_bed_vtp);
  for (const StagePlan* s : {&p.pack, &p.analysis, &p.surface, &p.mesh, &p.case_}) {
    ASSERT_TRUE(s->reused.is_object());
    EXPECT_TRUE(s->reused["reused"].get<bool>());
  }
  // Case-only outputs: no bed.csv in the directory either.
  const RunPlan only_case = plan_run({false, false, false, false, false, true}, kKeys, complete_report(),
                                     Directory{{"case/Allrun"}});
  EXPECT_EQ(built(only_case), 0);
  EXPECT_EQ(only_case.case_.reused["cache_key"], "case-key");
}

TEST(StageCache, OnlyTheCaseChangedRebuildsTheCaseOnTheMeshOnDiskElseOnANewMesh) {
  StageKeys changed = kKeys;
  changed.case_ = "other-case-key";
  const Wants with_mesh{true, true, true, false, true, true};
  const RunPlan on_disk = plan_run(with_mesh, changed, complete_report(), kEverything);
  EXPECT_TRUE(on_disk.case_.build);
  EXPECT_TRUE(on_disk.load_mesh);
  EXPECT_FALSE(on_disk.mesh.build || on_disk.surface.build || on_disk.pack.build || on_disk.analysis.build);
  EXPECT_TRUE(on_disk.load_bed);  // the case takes its geometry from the bed and records it
  // Without fluid.msh the mesh is made again, from a surface made again from the bed on disk.
  const Directory default_outputs{{"bed.csv", "bed.vtp", "radial_profile.csv", "contacts.csv", "case/Allrun"}};
  const RunPlan no_msh = plan_run(kDefault, changed, complete_report(), default_outputs);
  EXPECT_TRUE(no_msh.case_.build && no_msh.mesh.build && no_msh.surface.build);
  EXPECT_FALSE(no_msh.pack.build || no_msh.analysis.build);
  EXPECT_TRUE(no_msh.load_bed);
  EXPECT_FALSE(no_msh.load_mesh || no_msh.write_bed_csv);
}

// snappyHexMesh's cells (case.mesher = "snappy"): the case needs the surface's files and no mesh.
TEST(StageCache, ACaseOnSnappyHexMeshCellsBuildsNoMesh) {
  const Wants snappy{true, false, false, true, false, true, false};
  const RunPlan first = plan_run(snappy, kKeys, nullptr, Directory{});
  EXPECT_TRUE(first.surface.build && first.case_.build);
  EXPECT_FALSE(first.mesh.build || first.mesh.involved || first.load_mesh);
  // Only the case changed: rebuilt on the surface's files as they are, with no mesh read back.
  StageKeys changed = kKeys;
  changed.case_ = "other-case-key";
  const RunPlan case_only = plan_run(snappy, changed, complete_report(), kEverything);
  EXPECT_TRUE(case_only.case_.build);
  EXPECT_FALSE(case_only.surface.build || case_only.mesh.build || case_only.load_mesh || case_only.mesh.involved);
  // The fluid.msh the user asked for is still made.
  Wants with_mesh = snappy;
  with_mesh.mesh = true;
  EXPECT_TRUE(plan_run(with_mesh, kKeys, nullptr, Directory{}).mesh.build);
}

TEST(StageCache, OnlyTheMeshChangedRebuildsSurfaceMeshAndCaseOnTheSameBed) {
  StageKeys changed = kKeys;
  changed.mesh = "other-mesh-key";
  changed.case_ = "case-key-on-the-other-mesh";  // keys chain: the case's follows the mesh's
  const RunPlan p = plan_run(kDefault, changed, complete_report(), kEverything);
  EXPECT_TRUE(p.surface.build && p.mesh.build && p.case_.build);
  EXPECT_FALSE(p.pack.build || p.analysis.build);
  EXPECT_TRUE(p.load_bed);
}

TEST(StageCache, FilesDeletedByHandAreMadeAgainAndNothingElse) {
  // bed.vtp gone: the bed is read back to write it; no stage is built.
  Directory no_vtp = kEverything;
  no_vtp.files.erase("bed.vtp");
  const RunPlan vtp = plan_run(kDefault, kKeys, complete_report(), no_vtp);
  EXPECT_EQ(built(vtp), 0);
  EXPECT_TRUE(vtp.load_bed && vtp.write_bed_vtp);
  EXPECT_FALSE(vtp.write_bed_csv);
  // An analysis file gone: the analysis again.
  Directory no_profile = kEverything;
  no_profile.files.erase("contacts.csv");
  const RunPlan analysis = plan_run(kDefault, kKeys, complete_report(), no_profile);
  EXPECT_EQ(built(analysis), 1);
  EXPECT_TRUE(analysis.analysis.build && analysis.load_bed);
  // The case gone: made again on the mesh on disk.
  Directory no_case = kEverything;
  no_case.files.erase("case/Allrun");
  const RunPlan case_ = plan_run({true, true, true, false, true, true}, kKeys, complete_report(), no_case);
  EXPECT_EQ(built(case_), 1);
  EXPECT_TRUE(case_.case_.build && case_.load_mesh && case_.load_bed);
  // fluid.msh gone where it is an output: the mesh (and its surface) again, the case kept.
  Directory no_msh = kEverything;
  no_msh.files.erase("fluid.msh");
  const RunPlan mesh = plan_run({true, true, true, false, true, true}, kKeys, complete_report(), no_msh);
  EXPECT_TRUE(mesh.mesh.build && mesh.surface.build);
  EXPECT_FALSE(mesh.case_.build);
  // bed.csv gone when a stage must be built: the bed is packed again (same scene, same bed).
  Directory no_bed = no_profile;
  no_bed.files.erase("bed.csv");
  EXPECT_TRUE(plan_run(kDefault, kKeys, complete_report(), no_bed).pack.build);
}

TEST(StageCache, AChangedBedRebuildsEverythingAndForceIsNoEarlierRun) {
  StageKeys other{"new-pack", "new-analysis", "new-surface", "new-mesh", "new-case", "new-study"};
  const RunPlan p = plan_run(kDefault, other, complete_report(), kEverything);
  EXPECT_EQ(built(p), 5);
  EXPECT_TRUE(p.write_bed_csv && p.write_bed_vtp);
}

#ifdef BEDFORGE_HAVE_VOLUME_MESH
TEST(StageCache, AStudysRatioChangesTheMeshOnlyWhenTheMeshHasPrismLayers) {
  // A study's layers are decided at its coarsest level's lengths (layers_for_study), so with
  // layers a new ratio is a new finest mesh; without them only the study changes.
  auto keys = [](int layers, double ratio) {
    const std::string text = fmt::format("[container]\ndiameter_d = 5\n[particles]\ncount = 2\ndiameter_m = 0.003\n"
                                         "[mesh.layers]\ncount = {}\n[case]\nrun = true\n[case.convergence]\n"
                                         "ratio = {}\n[outputs]\nfiles = [\"case\"]\n",
                                         layers, ratio);
    return stage_keys(read_scene(toml::parse(text), "test"));
  };
  EXPECT_NE(keys(3, 1.3).mesh, keys(3, 1.2).mesh);
  EXPECT_EQ(keys(3, 1.3).surface, keys(3, 1.2).surface);
  EXPECT_EQ(keys(0, 1.3).mesh, keys(0, 1.2).mesh);
  EXPECT_NE(keys(0, 1.3).study, keys(0, 1.2).study);
}
#endif
