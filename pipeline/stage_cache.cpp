#include "pipeline/stage_cache.hpp"

#include <initializer_list>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/report.hpp"
#include "core/version.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "pipeline/surface_stage.hpp"
#endif

namespace bedforge::pipeline {

namespace {

// A stage's key: `inputs` (what else decides the stage: the version, an upstream key, a file's
// content) and the stage's own scene sections.
std::string scene_stage_key(const nlohmann::json& scene, nlohmann::json inputs,
                            std::initializer_list<const char*> sections) {
  for (const char* section : sections) inputs[section] = scene.contains(section) ? scene[section] : nlohmann::json();
  return stage_key(inputs);
}

std::string downstream_key(const nlohmann::json& scene, const std::string& upstream,
                           std::initializer_list<const char*> sections) {
  return scene_stage_key(scene, {{"upstream", upstream}}, sections);
}

}  // namespace

Wants run_wants(const Scene& scene) {
  // A case in pieces: its ranks read the bed from bed.csv, asked for or not.
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  const bool pieces = scene.wants("case") && scene.mesh.pieces > 1;
#else
  const bool pieces = false;  // no mesh stage, so no pieces
#endif
  return {scene.wants("positions") || pieces, scene.wants("vtp"),  scene.wants("analysis"),
          scene.wants("stl") || scene.case_params.snappy, scene.wants("mesh"), scene.wants("case"),
          !scene.case_params.snappy_cells, scene.case_params.convergence.levels > 0};
}

Wants pack_wants(const Scene& scene) { return {true, scene.wants("vtp"), false, false, false, false}; }

StageKeys stage_keys(const Scene& scene) {
  const nlohmann::json sc = scene.to_json();
  nlohmann::json inputs = {{"version", kVersion}};
  if (scene.algorithm == "import") inputs["file_key"] = stage_key(read_file(scene.import.file));
  StageKeys k;
  k.pack = scene_stage_key(sc, inputs, {"container", "particles", "packing"});
  k.analysis = downstream_key(sc, k.pack, {"analysis"});
  k.surface = downstream_key(sc, k.pack, {"contacts", "surface"});
  nlohmann::json mesh_inputs = {{"upstream", k.surface}};
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // A study's layers are decided as on its coarsest level ([case.convergence]: layers_for_study).
  if (scene.mesh.layers.room_scale != 1.0) mesh_inputs["layers_room_scale"] = scene.mesh.layers.room_scale;
#endif
  k.mesh = scene_stage_key(sc, mesh_inputs, {"mesh"});
  nlohmann::json without_study = sc;
  if (without_study.contains("case")) without_study["case"].erase("convergence");
  k.case_ = downstream_key(without_study, scene.case_params.snappy_cells ? k.surface : k.mesh, {"case"});
  const nlohmann::json none = nlohmann::json::object();
  k.study = stage_key({{"upstream", k.case_}, {"convergence", sc.value("case", none).value("convergence", none)}});
  return k;
}

RunPlan plan_run(const Wants& w, const StageKeys& keys, const nlohmann::json& previous,
                 const std::function<bool(const std::string&)>& exists) {
  // The earlier entry of a stage made with the same key, or null.
  auto entry = [&](const char* name, const std::string& key) -> nlohmann::json {
    if (!previous.contains("stages") || !previous["stages"].contains(name)) return nullptr;
    const nlohmann::json& e = previous["stages"][name];
    return e.value("cache_key", "") == key ? e : nlohmann::json();
  };
  auto all_exist = [&](const std::vector<std::string>& files) {
    for (const auto& f : files)
      if (!exists(f)) return false;
    return true;
  };
  const nlohmann::json pack = entry("pack", keys.pack), analysis = entry("analysis", keys.analysis),
                       surface = entry("surface", keys.surface), mesh = entry("mesh", keys.mesh),
                       case_ = entry("case", keys.case_);
  std::vector<std::string> analysis_files;
  if (!analysis.is_null())
    for (const auto& f : analysis.value("files", nlohmann::json::array())) analysis_files.push_back(f.get<std::string>());
  std::vector<std::string> surface_files;
#ifdef BEDFORGE_HAVE_CGAL
  if (w.stl) surface_files = surface_file_names();
#endif

  RunPlan p;
  // Backwards from the case: what is missing is built, and what a built stage needs in memory
  // is read back where its files allow it, else built too.
  p.case_.involved = w.case_;
  const bool case_has_study =
      !case_.is_null() && !case_.value("convergence", nlohmann::json::object()).value("levels", nlohmann::json::array()).empty();
  p.case_.build = w.case_ && (case_.is_null() || !exists("case/Allrun") || (w.study && !case_has_study));
  const bool mesh_on_disk = !mesh.is_null() && exists("fluid.msh");
  const bool case_needs_mesh = p.case_.build && w.case_on_mesh;
  p.mesh.involved = w.mesh || (w.case_ && w.case_on_mesh);
  p.mesh.build = (w.mesh || case_needs_mesh) && !mesh_on_disk;
  p.load_mesh = case_needs_mesh && !p.mesh.build;
  p.surface.involved = w.stl || p.mesh.involved;
  p.surface.build = p.mesh.build || (w.stl && (surface.is_null() || !all_exist(surface_files)));
  p.analysis.involved = w.analysis;
  p.analysis.build = w.analysis && (analysis.is_null() || analysis_files.empty() || !all_exist(analysis_files));
  p.redo_study = w.case_ && !p.case_.build && w.study && case_["convergence"].value("cache_key", "") != keys.study;
  const bool bed_needed = p.analysis.build || p.surface.build || p.case_.build || p.redo_study ||
                          (w.positions && !exists("bed.csv")) || (w.vtp && !exists("bed.vtp"));
  p.pack.involved = true;
  p.pack.build = pack.is_null() || (bed_needed && !exists("bed.csv"));
  p.load_bed = bed_needed && !p.pack.build;
  p.write_bed_csv = w.positions && (p.pack.build || !exists("bed.csv"));
  p.write_bed_vtp = w.vtp && (p.pack.build || !exists("bed.vtp"));

  // An involved stage that is not built has a matching entry, except after a report that lacked
  // it (a stage run on its own adds no key): it is then left out of the new report.
  auto reuse = [](StagePlan& s, nlohmann::json e) {
    if (!s.involved || s.build) return;
    s.involved = !e.is_null();
    if (e.is_null()) return;
    e["reused"] = true;
    s.reused = std::move(e);
  };
  reuse(p.pack, pack);
  reuse(p.analysis, analysis);
  reuse(p.surface, surface);
  reuse(p.mesh, mesh);
  reuse(p.case_, case_);
  return p;
}

}  // namespace bedforge::pipeline
