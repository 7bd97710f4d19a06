#include "pipeline/run_scene.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <memory>
#include <string>

#include "cases/case_writer.hpp"
#include "core/atomic_file.hpp"
#include "core/bed_io.hpp"
#include "core/error.hpp"
#include "core/report.hpp"
#include "core/stage_meter.hpp"
#include "core/version.hpp"
#include "meshing/surface/stl_io.hpp"
#include "pipeline/analysis_stage.hpp"
#include "pipeline/output_files.hpp"
#include "pipeline/pack_stage.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "pipeline/surface_stage.hpp"
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
#include "meshing/volume/gmsh_model.hpp"
#include "pipeline/case_stage.hpp"
#include "pipeline/convergence_study.hpp"
#include "pipeline/mesh_stage.hpp"
#include "pipeline/piece_stage.hpp"
#include "pipeline/pressure_drop_answer.hpp"
#endif

namespace bedforge::pipeline {

namespace fs = std::filesystem;

namespace {

// The output directory must be one, or a path that can become one: said before any work.
void check_output_directory(const fs::path& dir) {
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw InputError(fmt::format("output directory {}: it exists and is not a directory; allowed: a directory, or a "
                                 "path where one can be made",
                                 dir.string()));
  fs::path existing = fs::absolute(dir);
  while (!fs::exists(existing)) existing = existing.parent_path();
  if (!fs::is_directory(existing) || ::access(existing.c_str(), W_OK) != 0)
    throw InputError(fmt::format("output directory {}: {} is not a directory this user can write in; allowed: a "
                                 "writable place",
                                 dir.string(), existing.string()));
}

}  // namespace

void run_scene(const Scene& scene, const fs::path& dir, const RunOptions& opt, const Console& console) {
  check_output_directory(dir);
  const nlohmann::json previous =
      opt.force || !fs::exists(dir / "report.json") ? nlohmann::json() : Report::load_or_new(dir).data();
  const StageKeys keys = stage_keys(scene);
  const RunPlan plan = plan_run(opt.wants, keys, previous, [&dir](const std::string& f) { return fs::exists(dir / f); });
  if (plan.case_.build) cases::refuse_existing_case(dir / "case", opt.overwrite);  // before the long stages
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // A case in pieces: no whole surface or mesh in this process, the ranks make the pieces.
  const bool in_pieces = scene.mesh.pieces > 1;
  // A case in pieces is refused by its ranks, each against its own machine's memory (mpirun may
  // spread them over several: piece_directory).
  if (plan.mesh.build && !in_pieces) refuse_mesh_beyond_memory(scene, available_memory_bytes());
  // Without OpenFOAM the case is written and not solved, said now and by the exit status.
  const std::string missing = plan.case_.build && scene.case_params.run
                                  ? cases::missing_openfoam_program(scene.case_params.processors)
                                  : std::string();
  Scene unsolved_scene;
  if (!missing.empty()) {
    console.line(fmt::format("case: OpenFOAM's {} is not on PATH: the case will be written but not solved (install "
                             "OpenFOAM, e.g. apt-get install openfoam, then run {}/Allrun, or this command again with --overwrite)",
                             missing, (dir / "case").string()));
    unsolved_scene = scene;
    unsolved_scene.case_params.run = false;
    unsolved_scene.case_params.convergence.levels = 0;
  }
  const Scene& case_scene = missing.empty() ? scene : unsolved_scene;
#endif

  // Results of other stages in DIR may belong to another bed: the report starts afresh.
  Report report;
  report.set_provenance(kVersion, scene.to_json(), scene.seed);
  auto record = [&report](const char* name, nlohmann::json entry, const std::string& key) {
    entry["cache_key"] = key;
    report.set_stage(name, std::move(entry));
  };
  auto reuse = [&](const char* name, const StagePlan& s, const std::string& what) {
    if (s.reused.is_null()) return;
    console.line(fmt::format("{}: reused {}", name, what));
    report.set_stage(name, s.reused);
  };

  Bed bed;
  if (plan.pack.build) {
    PackStage pack = pack_stage(scene, console);
    bed = std::move(pack.bed);
    record("pack", std::move(pack.report), keys.pack);
  } else {
    if (plan.load_bed) {  // bed.csv keeps 17 digits: the bed read back is the bed packed
      bed = read_bed_text(dir / "bed.csv", 1.0).bed;
      // A period set by a target void fraction is the spheres', which bed.csv records.
      if (scene.soft_sphere.target_void_fraction == 0.0) bed.container = scene.container;
    }
    reuse("pack", plan.pack,
          fmt::format("the bed in {} (container, particles and packing unchanged; --force redoes it)", dir.string()));
  }

#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // Now with the bed's narrow gaps, whose cells the scene alone cannot foresee: before the surface.
  MeshEstimate estimate;
  if (plan.mesh.build && !in_pieces) {
    const double available = available_memory_bytes();
    estimate = refuse_mesh_beyond_memory(scene, bed, available);
    console.line(estimate_line(estimate, available));
  }
#endif

  OutputFiles files;
  const Provenance prov{kVersion, scene.seed, scene.to_json()};
  if (plan.write_bed_csv) files.add("bed.csv", bed_to_csv(bed, prov));
  if (plan.write_bed_vtp) files.add("bed.vtp", bed_to_vtp(bed, prov));
  files.add("scene.toml", "# scene as run by bedforge " + std::string(kVersion) + "\n" + scene_to_toml(scene.table));

  if (plan.analysis.build) {
    AnalysisStage a = analysis_stage(bed, scene.analysis, console);
    for (auto& [name, csv] : a.csv_files) files.add(name, std::move(csv));
    record("analysis", std::move(a.report), keys.analysis);
  } else {
    reuse("analysis", plan.analysis, fmt::format("the analysis in {} (bed and [analysis] unchanged)", dir.string()));
  }

#ifdef BEDFORGE_HAVE_CGAL
  std::shared_ptr<const meshing::FluidSurface> surface;
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  if (plan.surface.build && !in_pieces) {
#else
  if (plan.surface.build) {
#endif
    SurfaceStage s = surface_stage(bed, scene.surface, dir / "bad_triangles.vtp", console);
    if (opt.wants.stl) add_surface_files(s.surface, files);
    surface = std::move(s.surface);
    record("surface", std::move(s.report), keys.surface);
  } else {
    reuse("surface", plan.surface,
          opt.wants.stl ? fmt::format("the surface in {} (bed, [contacts] and [surface] unchanged)", dir.string())
                        : std::string("the surface's record (bed, [contacts] and [surface] unchanged; its mesh is "
                                      "reused)"));
  }
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  std::shared_ptr<const meshing::PolyMesh> mesh;
  if (in_pieces) {
    // Made by the case stage's ranks.
  } else if (plan.mesh.build) {
    const fs::path msh = opt.wants.mesh ? dir / ".fluid.partial.msh" /* gmsh picks the format by extension */ : fs::path();
    if (opt.wants.mesh) files.add_made("fluid.msh", msh);
    MeshStage m = mesh_stage(surface->fluid, surface->exact_volume_m3, bed, scene.surface, scene.mesh, msh, dir / "bad_cells.vtk", console);
    mesh = std::shared_ptr<const meshing::PolyMesh>(m.volume, &m.volume->mesh);
    m.report["estimate"] = to_json(estimate);
    record("mesh", std::move(m.report), keys.mesh);
  } else {
    if (plan.load_mesh) mesh = std::make_shared<const meshing::PolyMesh>(meshing::read_msh(dir / "fluid.msh"));
    reuse("mesh", plan.mesh,
          opt.wants.mesh ? fmt::format("{} (surface and [mesh] unchanged)", (dir / "fluid.msh").string())
                         : std::string("the mesh's record (surface and [mesh] unchanged; its case is reused)"));
  }
  // The case needs the volume mesh only, or for snappyHexMesh's cells the surface (read back when
  // it was not built in this run).
  std::shared_ptr<const meshing::TriangleMesh> fluid;
  if (plan.case_.build && scene.case_params.snappy_cells)
    fluid = surface ? std::shared_ptr<const meshing::TriangleMesh>(surface, &surface->fluid)
                    : std::make_shared<const meshing::TriangleMesh>(meshing::read_stl_ascii_by_patch(dir / "fluid.stl"));
  surface.reset();
#endif
  files.write(dir);

#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // The earlier run's study, whose coarser levels a new one reuses where they still hold.
  const nlohmann::json none = nlohmann::json::object(),
                       earlier_study = previous.is_object()
                                           ? previous.value("stages", none).value("case", none).value("convergence", nlohmann::json())
                                           : nlohmann::json();
  const bool study = case_scene.case_params.convergence.levels > 0;
  // The answer (the pressure drop with its band and reference) into the case's entry, drawn in
  // pressure_drop.svg; none for a case not solved.
  auto answer = [&](nlohmann::json& entry, const ConvergenceStudy* s) {
    fs::remove(dir / "pressure_drop.svg");
    entry.erase("answer");
    if (const std::optional<PressureDropAnswer> a = pressure_drop_answer(scene, entry, s)) {
      entry["answer"] = a->to_json();
      write_file_atomically(dir / "pressure_drop.svg", answer_svg(*a));
    }
  };
  if (plan.case_.build) {
    const std::optional<CasePieces> pieces =
        in_pieces ? std::optional(case_pieces(bed, scene.surface, scene.mesh.pieces, dir, console)) : std::nullopt;
    const CaseStage c = case_stage(std::move(mesh), std::move(fluid), bed, case_scene.case_params, prov,
                                   read_file(dir / "scene.toml"), scene.case_params.snappy ? dir / "fluid.stl" : fs::path(),
                                   dir / "case", opt.overwrite, treated_solid(scene.surface, bed), console,
                                   pieces ? &*pieces : nullptr);
    nlohmann::json entry = c.report;
    std::optional<ConvergenceStudy> s;
    if (study) {
      s = add_convergence_study(scene, bed, finest_level(c, report, keys.case_), earlier_study, dir, console, entry);
      entry["convergence"]["cache_key"] = keys.study;
    }
    answer(entry, s ? &*s : nullptr);
    // An unsolved case must not pass for a solved one when OpenFOAM is there next time.
    record("case", std::move(entry), missing.empty() ? keys.case_ : keys.case_ + "-not-solved");
  } else if (plan.case_.involved) {
    reuse("case", plan.case_, fmt::format("{} (mesh and [case] unchanged)", (dir / "case").string()));
    // A changed study is redone from the case's finest level, solving only the levels that changed.
    nlohmann::json entry = plan.case_.reused;
    if (plan.redo_study) {
      const std::optional<double> exact = earlier_study.contains("exact_pa_m")
                                              ? std::optional(earlier_study["exact_pa_m"].get<double>())
                                              : std::nullopt;
      const ConvergenceStudy s = add_convergence_study(scene, bed, study_level_from_json(earlier_study["levels"][0], exact),
                                                       earlier_study, dir, console, entry);
      entry["convergence"]["cache_key"] = keys.study;
      answer(entry, &s);
    } else if (!study) {
      remove_convergence_study(entry);
      answer(entry, nullptr);
    }
    report.set_stage("case", std::move(entry));
  }
  if (plan.case_.involved && !study) fs::remove_all(dir / "convergence");  // an earlier run's study
#endif
  report.save(dir);
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // The answer is the run's last word, whatever was reused.
  const nlohmann::json& stages = report.data()["stages"];
  if (stages.contains("case") && stages["case"].contains("answer")) {
    for (const auto& line : stages["case"]["answer"]["lines"]) console.line(line.get<std::string>());
    console.line(fmt::format("  picture: {}; every level: {} (stages.case.convergence)", (dir / "pressure_drop.svg").string(),
                             (dir / "report.json").string()));
  }
  if (!missing.empty())
    throw NotSolvedError(fmt::format("the case in {} was written but not solved: OpenFOAM's {} is not on PATH",
                                     (dir / "case").string(), missing));
#endif
}

}  // namespace bedforge::pipeline
