#include "app/commands.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "analysis/bed_analysis.hpp"
#include "analysis/contact_statistics.hpp"
#include "analysis/void_fraction.hpp"
#include "app/scene.hpp"
#include "core/atomic_file.hpp"
#include "core/bed_io.hpp"
#include "core/error.hpp"
#include "core/progress.hpp"
#include "core/report.hpp"
#include "core/stage_meter.hpp"
#include "core/version.hpp"
#include "packer/soft_sphere.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "cases/openfoam_case.hpp"
#include "meshing/defect_locations.hpp"
#include "meshing/fluid_surface.hpp"
#include "meshing/stl_io.hpp"
#include "meshing/surface_checks.hpp"
#include "meshing/vtp_io.hpp"
#endif
#ifdef BEDFORGE_HAVE_GMSH
#include "meshing/volume_mesh.hpp"
#endif

namespace bedforge {

namespace fs = std::filesystem;

namespace {

struct Console {
  bool progress = Progress::wanted_by_default();
  bool quiet = false;
  void line(const std::string& s) const {
    if (!quiet) std::printf("%s\n", s.c_str());
  }
};

// Ends a stage: its time and peak memory into `stage`, appended to its one-line summary, which
// is stored and printed.
void finish_stage(nlohmann::json& stage, const StageMeter& meter, const std::string& line, const Console& console) {
  meter.record(stage);
  stage["summary"] = fmt::format("{}, {:.2f} s, {:.0f} MB", line, stage["time_s"].get<double>(),
                                 stage["peak_memory_mb"].get<double>());
  console.line(stage["summary"].get<std::string>());
}

// Files of one run, written together at the end so a failure leaves nothing half-made.
// Large files are streamed by a writer at that point instead of held as a string.
struct Outputs {
  using Writer = std::function<void(std::ostream&)>;
  std::vector<std::pair<std::string, Writer>> files;
  void add(std::string name, std::string contents) {
    auto text = std::make_shared<const std::string>(std::move(contents));
    add_writer(std::move(name), [text](std::ostream& out) { out << *text; });
  }
  void add_writer(std::string name, Writer w) { files.emplace_back(std::move(name), std::move(w)); }
  // A file a library wrote itself (gmsh) at `temporary`, renamed to `name` with the others.
  void add_made(std::string name, fs::path temporary) { made.emplace_back(std::move(name), std::move(temporary)); }
  void write(const fs::path& dir) {
    for (const auto& [name, writer] : files) write_file_atomically(dir / name, writer);
    for (const auto& [name, temporary] : made) fs::rename(temporary, dir / name);
    made.clear();
  }
  ~Outputs() {
    std::error_code ec;
    for (const auto& m : made) fs::remove(m.second, ec);
  }
  std::vector<std::pair<std::string, fs::path>> made;
};

// An imported bed is checked before any stage builds on it: a centre outside the container or
// below the floor means the file's frame or unit is not the one the scene gives. Overlaps are
// measured and reported, not refused: the surface stage says which treatment can handle them.
nlohmann::json check_imported(const Bed& bed, const std::string& file) {
  const double d = sauter_mean(bed.diameters);
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const double r = 0.5 * bed.diameters[i];
    WallContact walls[Container::kMaxWallContacts];
    const int nw = bed.container->wall_contacts(bed.centres[i], r, walls);
    double worst = 0.0;
    for (int k = 0; k < nw; ++k) worst = std::max(worst, walls[k].overlap);
    const auto& c = bed.centres[i];
    if (worst > r || c.z() < 0.0)
      throw InputError(fmt::format("{}: sphere {} (centre {:.6g}, {:.6g}, {:.6g} m) lies {} the {}; allowed: centres "
                                   "inside the container, above the floor at z = 0 (check packing.units, "
                                   "packing.origin_m and [container])",
                                   file, i + 1, c.x(), c.y(), c.z(), c.z() < 0.0 ? "below the floor of" : "outside",
                                   bed.container->kind()));
  }
  const analysis::ContactStatistics cs = analysis::contact_statistics(bed, 0.0);
  return {{"max_pair_overlap_d", cs.max_pair_overlap / d},
          {"max_wall_overlap_d", cs.max_wall_overlap / d},
          {"max_floor_penetration_d", cs.max_floor_penetration / d}};
}

// Packing stage: the packed (or imported) bed and its report entry.
struct PackStage {
  Bed bed;
  nlohmann::json report;
};

PackStage pack_stage(const Scene& scene, const Console& console) {
  const StageMeter meter;
  PackStage out;
  if (scene.algorithm == "import") {
    const ImportedBed& imported = *scene.import.bed;
    out.bed = imported.bed;
    out.bed.container = scene.container;
    const auto& o = scene.import.origin_m;
    out.report = {{"algorithm", "import"},
                  {"file", scene.import.file.string()},
                  {"format", scene.table["packing"]["format"].value_or(std::string("xyzd"))},
                  {"to_metres", scene.import.to_metres},
                  {"origin_m", {o.x(), o.y(), o.z()}},
                  {"header", imported.header}};
    out.report["overlaps"] = check_imported(out.bed, scene.import.file.string());
  } else {
    Progress progress("pack", console.progress);
    packer::PackResult r =
        scene.algorithm == "monte-carlo"
            ? packer::pack_monte_carlo(scene.monte_carlo, scene.sizes, *scene.container, scene.count, scene.seed, progress)
            : packer::pack_soft_sphere(scene.soft_sphere, scene.sizes, *scene.container, scene.count, scene.seed, progress);
    out.bed = std::move(r.bed);
    out.report = std::move(r.info);
  }
  out.report["spheres"] = out.bed.size();
  out.report["container_m"] = out.bed.container->to_json();
  out.report["void_fraction"] = analysis::void_fraction_summary(out.bed, scene.analysis);
  const auto& vf = out.report["void_fraction"];
  std::string line;
  if (scene.algorithm == "import") {
    line = fmt::format("import: {} spheres from {}, max overlap {:.2g} d (wall {:.2g} d)", out.bed.size(),
                       scene.import.file.string(), out.report["overlaps"]["max_pair_overlap_d"].get<double>(),
                       out.report["overlaps"]["max_wall_overlap_d"].get<double>());
  } else if (scene.algorithm == "monte-carlo") {
    line = fmt::format("pack (monte-carlo): {} spheres in a {}, {} cycles ({:.0f} per s), acceptance {:.2f}, {} of {} "
                       "shakes settled, no overlap",
                       out.bed.size(), out.bed.container->kind(), out.report["cycles"].get<long>(),
                       out.report["cycles_per_second"].get<double>(), out.report["mean_acceptance"].get<double>(),
                       out.report["shakes"].size() - out.report["unsettled_shakes"].get<std::size_t>(),
                       out.report["shakes"].size());
  } else {
    line = fmt::format("pack ({} {}): {} spheres, {} iterations, max overlap {:.2g} d (tol {:.2g}), residual {:.2g}",
                       out.report["algorithm"].get<std::string>(),
                       out.report["parameters"]["mode"].get<std::string>(), out.bed.size(),
                       out.report["iterations"].get<long>(), out.report["max_pair_overlap_d"].get<double>(),
                       out.report["overlap_tolerance_d"].get<double>(), out.report["force_residual_rms"].get<double>());
  }
  line += fmt::format(", eps {:.4f} (central {})", vf["whole_bed"].get<double>(),
                      vf["central_slab"].is_null() ? std::string("n/a") : fmt::format("{:.4f}", vf["central_slab"].get<double>()));
  finish_stage(out.report, meter, line, console);
  return out;
}

void add_analysis(const Bed& bed, const analysis::AnalysisParams& params, Report& report, Outputs& files,
                  const Console& console) {
  const StageMeter meter;
  analysis::AnalysisResult a = analysis::analyse_bed(bed, params);
  for (auto& [name, csv] : a.csv_files) files.add(name, csv);
  finish_stage(a.report, meter, a.summary, console);
  report.set_stage("analysis", a.report);
}

#ifdef BEDFORGE_HAVE_CGAL
// Surface stage: treated contacts, the fluid-domain surface checked by CGAL, STL files.
// Returns the surface for the mesh stage; writes the STL files when `write_files`. A surface
// failing the angle gate writes its bad triangles to DIR/bad_triangles.vtp and throws.
std::shared_ptr<const meshing::FluidSurface> add_surface(const Bed& bed, const meshing::SurfaceParams& p,
                                                         const std::string& version, bool write_files,
                                                         const std::filesystem::path& dir, Report& report,
                                                         Outputs& files, const Console& console) {
  const StageMeter meter;
  auto built = std::make_shared<meshing::FluidSurface>(meshing::build_fluid_surface(bed, p));
  meshing::FluidSurface& fs = *built;
  const double built_at = meter.seconds();
  const meshing::SurfaceCheck check = meshing::check_surface(fs.fluid, p.self_intersection_limit);
  nlohmann::json& j = fs.report;
  j["time_build_s"] = built_at;
  j["time_check_s"] = meter.seconds() - built_at;
  j["check"] = check.to_json();
  const double exact = j["fluid_volume_exact_m3"].get<double>();
  j["fluid_volume_mesh_m3"] = check.volume;
  if (!check.manifold || !check.closed || check.self_intersecting) {
    const std::string where = meshing::describe_defects(check);
    throw std::runtime_error(fmt::format("the fluid surface is not valid ({}); {} defective edges, first at{} please "
                                         "report it with the bed",
                                         check.to_json().dump(), check.defects.size(), where));
  }
  j["fluid_volume_relative_error"] = (check.volume - exact) / exact;
  if (j["min_angle_deg"].get<double>() < p.min_angle_deg) {
    // Say where the needles and slivers are: the nearest particle to each, and all of them in a
    // file for ParaView.
    const meshing::TriangleMesh bad = meshing::triangles_below_angle(fs.fluid, p.min_angle_deg);
    std::vector<Eigen::Vector3d> centroids;
    for (std::size_t v = 0; v < bad.points.size(); v += 3)
      centroids.push_back((bad.points[v] + bad.points[v + 1] + bad.points[v + 2]) / 3.0);
    const meshing::DefectLocations where = meshing::locate_defects(bed, centroids, "triangles");
    const std::filesystem::path path = dir / "bad_triangles.vtp";
    write_file_atomically(path, [&](std::ostream& out) {
      meshing::write_vtp(out, bad, "bedforge " + version + " surface triangles below surface.min_angle_deg, lengths in m");
    });
    throw ConvergenceError(fmt::format(
        "surface: {} triangles have an angle below surface.min_angle_deg = {} deg (smallest {:.2f} deg), most near {}; "
        "written to {}. Refine where contacts meet (surface.contact_edge_length_d), widen the gaps ([contacts]), "
        "move the clip window, or lower surface.min_angle_deg",
        bad.triangles.size(), p.min_angle_deg, j["min_angle_deg"].get<double>(), where.summary, path.string()));
  }
  if (write_files) {
    files.add_writer("fluid.stl", [built](std::ostream& out) { meshing::write_stl_ascii_by_patch(out, built->fluid); });
    for (std::size_t k = 0; k < fs.fluid.patches.size(); ++k)
      files.add_writer("fluid_" + fs.fluid.patches[k] + ".stl", [built, k, version](std::ostream& out) {
        meshing::write_stl_binary(out, built->fluid, static_cast<int>(k), "bedforge " + version + " " + built->fluid.patches[k]);
      });
    files.add_writer("bed.stl", [built, version](std::ostream& out) {
      meshing::write_stl_binary(out, built->bed, -1, "bedforge " + version + " bed solid");
    });
    files.add_writer("fluid.vtp", [built, version](std::ostream& out) {
      meshing::write_vtp(out, built->fluid, "bedforge " + version + " fluid-domain surface, lengths in m");
    });
  }
  std::string line = fmt::format(
      "surface ({}, {} contacts treated): {} triangles, closed, {}, volume error {:.2e}, chordal deviation {:.2e} d, "
      "min angle {:.1f} deg, smallest gap {:.3g} d",
      j["parameters"]["treatment"].get<std::string>(),
      j["contacts_treated"]["particle_particle"].get<long>() + j["contacts_treated"]["particle_wall"].get<long>(),
      j["triangles"].get<std::size_t>(),
      check.self_intersections_checked ? "no self-intersection" : "self-intersections not checked",
      j["fluid_volume_relative_error"].get<double>(), j["chordal_deviation_d"].get<double>(),
      j["min_angle_deg"].get<double>(),
      std::min(j["smallest_gap_d"]["particle_particle"].get<double>(), j["smallest_gap_d"]["particle_wall"].get<double>()));
  if (j.contains("clip")) {
    line += fmt::format(", clipped at {:.3f}-{:.3f} d", j["clip"]["inlet"]["used_d"].get<double>(),
                        j["clip"]["outlet"]["used_d"].get<double>());
    const long opened = j["clip"]["inlet"]["contacts_opened"].get<long>() + j["clip"]["outlet"]["contacts_opened"].get<long>();
    if (opened > 0) line += fmt::format(" ({} contacts opened there)", opened);
  }
  finish_stage(j, meter, line, console);
  report.set_stage("surface", j);
  return built;
}

// Case stage: the OpenFOAM case in DIR/case, run when asked.
void add_case(const meshing::PolyMesh& mesh, const Bed& bed, const cases::CaseParams& p, const Provenance& prov,
              const std::string& scene_toml, const std::string& fluid_stl, const fs::path& dir, bool overwrite,
              Report& report, const Console& console) {
  const StageMeter meter;
  cases::CaseGeometry g;
  g.d_ref = sauter_mean(bed.diameters);
  const Container& c = *bed.container;
  g.cross_section_area = c.cross_section_area();
  g.lateral_bounds = c.lateral_bounds();
  g.aspect_ratio = 4.0 * g.cross_section_area / c.wall_perimeter() / g.d_ref;  // hydraulic diameter over d
  g.inlet_z = std::numeric_limits<double>::infinity();
  g.outlet_z = -g.inlet_z;
  for (const auto& x : mesh.points) g.inlet_z = std::min(g.inlet_z, x.z()), g.outlet_z = std::max(g.outlet_z, x.z());
  g.bed_top = analysis::bed_height(bed);
  const fs::path case_dir = dir / "case";
  const std::string note = fmt::format("bedforge {}, seed {}", prov.version, prov.seed ? std::to_string(*prov.seed) : "none");
  nlohmann::json j = cases::write_case(case_dir, overwrite, mesh, g, p, note, scene_toml, bed_to_csv(bed, prov), fluid_stl);
  std::string line = fmt::format("case: {} cells in {}, Re_p {}, u {:.3g} m/s, bed section eps {:.4f}",
                                 mesh.cells, case_dir.string(), p.reynolds, j["velocity_m_s"].get<double>(),
                                 j["section"]["void_fraction_mesh"].get<double>());
  if (p.run) {
    Progress progress("case", console.progress);
    const nlohmann::json flow = cases::run_case(case_dir, j, progress);
    j["flow"] = flow;
    if (p.run_snappy) line += fmt::format("; snappyHexMesh made {} cells", flow["mesh"].value("cells", 0L));
    line += fmt::format("; simpleFoam {} in {} iterations (residuals U {:.1e}, p {:.1e}), dp/L {:.4g} Pa/m = {:.3f} x "
                        "Eisfeld & Schnitzlein",
                        flow["converged"].get<bool>() ? "converged" : "NOT converged", flow["iterations"].get<long>(),
                        flow["final_initial_residual"]["U"].get<double>(),
                        flow["final_initial_residual"]["p"].get<double>(),
                        flow["pressure_gradient_bed_pa_m"].get<double>(),
                        flow["ratio_to_eisfeld_schnitzlein"].get<double>());
  }
  finish_stage(j, meter, line, console);
  report.set_stage("case", j);
}
#endif

#ifdef BEDFORGE_HAVE_GMSH
// Mesh stage: gmsh's volume mesh of the surface, held to the quality gate; fluid.msh when `write_msh`.
std::shared_ptr<const meshing::VolumeMesh> add_mesh(const meshing::TriangleMesh& surface, double exact_volume,
                                                    const Bed& bed, const meshing::VolumeMeshParams& p,
                                                    bool write_msh, const fs::path& dir, Report& report,
                                                    Outputs& files, const Console& console) {
  const StageMeter meter;
  fs::create_directories(dir);
  const fs::path msh = write_msh ? dir / ".fluid.partial.msh"  /* gmsh picks the format by extension */ : fs::path();
  if (write_msh) files.add_made("fluid.msh", msh);
  Progress progress("mesh", console.progress);
  const double d = sauter_mean(bed.diameters);
  auto vm = std::make_shared<meshing::VolumeMesh>(
      meshing::build_volume_mesh(surface, bed, d, p, msh, dir / "bad_cells.vtk", progress));
  progress.finish();
  nlohmann::json& j = vm->report;
  j["parameters"] = meshing::to_json(p);
  j["fluid_volume_exact_m3"] = exact_volume;
  j["fluid_volume_relative_error"] = (vm->quality.total_volume - exact_volume) / exact_volume;
  const auto& q = j["quality"];
  std::string line = fmt::format(
      "mesh ({}): {} cells, max non-orthogonality {:.1f} deg (mean {:.1f}, {} faces > 70), max skewness {:.2f}, "
      "max aspect ratio {:.1f}, volume error {:.2e}",
      j["algorithm"].get<std::string>(), vm->mesh.cells, q["max_non_orthogonality_deg"].get<double>(),
      q["mean_non_orthogonality_deg"].get<double>(), q["faces_over_70_deg"].get<long>(), q["max_skewness"].get<double>(),
      q["max_aspect_ratio"].get<double>(), j["fluid_volume_relative_error"].get<double>());
  if (j.contains("layers")) {
    const auto& l = j["layers"];
    line += fmt::format("; {} prism layers, mean thickness {:.3g} d, {} of {} stacks at full thickness",
                        p.layers.count, l["mean_thickness_d"].get<double>(), l["stacks_at_full_thickness"].get<long>(),
                        l["stacks"].get<long>());
  }
  finish_stage(j, meter, line, console);
  report.set_stage("mesh", j);
  return vm;
}
#endif

Provenance provenance_of(const Scene& scene) { return {kVersion, scene.seed, scene.to_json()}; }

// A stage's cache key: `inputs` (what else decides the stage: the version, an upstream stage's
// key, a file's content) and the stage's own scene sections.
std::string scene_stage_key(const Scene& scene, nlohmann::json inputs, std::initializer_list<const char*> sections) {
  const nlohmann::json sc = scene.to_json();
  for (const char* section : sections) inputs[section] = sc.contains(section) ? sc[section] : nlohmann::json();
  return stage_key(inputs);
}

// The pack stage's: the sections that decide the bed, the version that packs it and, for an
// imported bed, the file's content. Each later stage's builds on the key of the stage before.
std::string pack_key(const Scene& scene) {
  nlohmann::json inputs = {{"version", kVersion}};
  if (scene.algorithm == "import") inputs["file_key"] = stage_key(read_file(scene.import.file));
  return scene_stage_key(scene, inputs, {"container", "particles", "packing"});
}
#ifdef BEDFORGE_HAVE_CGAL
std::string downstream_key(const Scene& scene, const std::string& upstream_key, std::initializer_list<const char*> sections) {
  return scene_stage_key(scene, {{"upstream", upstream_key}}, sections);
}
#endif

// The report entry of stage `name` an earlier run left in DIR, when it was made with the same
// key and the files it wrote (`files`) are still there; null otherwise.
nlohmann::json reusable_stage(const nlohmann::json& previous, const fs::path& dir, const std::string& name,
                              const std::string& key, const std::vector<std::string>& files) {
  if (!previous.contains("stages") || !previous["stages"].contains(name)) return nullptr;
  const nlohmann::json& stage = previous["stages"][name];
  if (stage.value("cache_key", "") != key) return nullptr;
  for (const auto& f : files)
    if (!fs::exists(dir / f)) return nullptr;
  nlohmann::json out = stage;
  out["reused"] = true;
  return out;
}

// The bed an earlier run left in DIR, when its pack stage had the same key (bed.csv keeps 17
// digits, so the bed read back is the bed packed).
std::optional<PackStage> reusable_pack(const nlohmann::json& previous, const fs::path& dir, const std::string& key,
                                       const Scene& scene, const Console& console) {
  nlohmann::json stage = reusable_stage(previous, dir, "pack", key, {"bed.csv"});
  if (stage.is_null()) return std::nullopt;
  PackStage out;
  out.bed = read_bed_text(dir / "bed.csv", 1.0).bed;
  out.bed.container = scene.container;
  out.report = std::move(stage);
  console.line(fmt::format("pack: reused the bed in {} (container, particles and packing unchanged; --force redoes "
                           "it)",
                           dir.string()));
  return out;
}

// `run`, `pack` and `import`: a scene (file plus overrides) into DIR. `run` follows the scene's
// outputs; `pack` and `import` always write the bed and leave the analysis to `analyse`.
struct RunOptions {
  bool analysis = false;   // write the analysis (profiles, contacts)
  bool positions = true;   // write bed.csv
  bool overwrite = false;  // replace DIR/case
  bool force = false;      // redo every stage, even those DIR holds for unchanged inputs
};

int run_scene(const Scene& scene, const fs::path& dir, const RunOptions& opt, const Console& console) {
  // Stage results an earlier run left in DIR are reused when their keys match: each key hashes
  // the stage's scene sections and the key of the stage before, so a change reaches downstream.
  const nlohmann::json previous =
      opt.force || !fs::exists(dir / "report.json") ? nlohmann::json() : Report::load_or_new(dir).data();
  const std::string key = pack_key(scene);
  std::optional<PackStage> reused = reusable_pack(previous, dir, key, scene, console);
  PackStage pack = reused ? std::move(*reused) : pack_stage(scene, console);
  pack.report["cache_key"] = key;
  Report report;  // results of other stages in DIR may belong to another bed: start afresh
  report.set_provenance(kVersion, scene.to_json(), scene.seed);
  report.set_stage("pack", pack.report);
  Outputs files;
  const Provenance prov = provenance_of(scene);
  if (opt.positions) files.add("bed.csv", bed_to_csv(pack.bed, prov));
  if (scene.wants("vtp")) files.add("bed.vtp", bed_to_vtp(pack.bed, prov));
  files.add("scene.toml", "# scene as run by bedforge " + std::string(kVersion) + "\n" + scene_to_toml(scene.table));
  if (opt.analysis) add_analysis(pack.bed, scene.analysis, report, files, console);
#ifdef BEDFORGE_HAVE_CGAL
  const std::string surface_key = downstream_key(scene, key, {"contacts", "surface"});
  const bool write_stl = scene.wants("stl") || scene.case_params.snappy;
#ifdef BEDFORGE_HAVE_GMSH
  // The mesh is reused from DIR/fluid.msh, written when the scene's outputs name `mesh`; the
  // case (with its flow results, when it was run) from DIR/case.
  const std::string mesh_key = downstream_key(scene, surface_key, {"mesh"});
  const nlohmann::json mesh_reused =
      scene.needs_mesh() ? reusable_stage(previous, dir, "mesh", mesh_key, {"fluid.msh"}) : nlohmann::json();
  const std::string case_key = downstream_key(scene, mesh_key, {"case"});
  const nlohmann::json case_reused = scene.wants("case") && !mesh_reused.is_null()
                                         ? reusable_stage(previous, dir, "case", case_key, {"case/Allrun"})
                                         : nlohmann::json();
  if (scene.wants("case") && case_reused.is_null())
    cases::refuse_existing_case(dir / "case", opt.overwrite);  // before the long stages, not after
#else
  const nlohmann::json mesh_reused;
#endif
  // The surface is reused only when no mesh is built from it: a mesh is made from the surface
  // in memory, never from its STL read back.
  nlohmann::json surface_reused;
  if (scene.needs_surface() && (!scene.needs_mesh() || !mesh_reused.is_null()))
    surface_reused = reusable_stage(previous, dir, "surface", surface_key,
                                    write_stl ? std::vector<std::string>{"fluid.stl", "bed.stl", "fluid.vtp"}
                                              : std::vector<std::string>{});
  std::shared_ptr<const meshing::FluidSurface> surface;
  if (!surface_reused.is_null()) {
    console.line(fmt::format("surface: reused the surface in {} (bed, [contacts] and [surface] unchanged)", dir.string()));
    report.set_stage("surface", surface_reused);
  } else if (write_stl || (scene.needs_mesh() && mesh_reused.is_null())) {
    surface = add_surface(pack.bed, scene.surface, kVersion, write_stl, dir, report, files, console);
    report.set_cache_key("surface", surface_key);
  }
#endif
#ifdef BEDFORGE_HAVE_GMSH
  std::shared_ptr<const meshing::PolyMesh> mesh;
  if (!mesh_reused.is_null()) {
    console.line(fmt::format("mesh: reused {} (surface and [mesh] unchanged)", (dir / "fluid.msh").string()));
    report.set_stage("mesh", mesh_reused);
    if (scene.wants("case") && case_reused.is_null())
      mesh = std::make_shared<const meshing::PolyMesh>(meshing::read_msh(dir / "fluid.msh"));
  } else if (scene.needs_mesh()) {
    auto vm = add_mesh(surface->fluid, surface->report["fluid_volume_exact_m3"].get<double>(), pack.bed, scene.mesh,
                       scene.wants("mesh"), dir, report, files, console);
    mesh = std::shared_ptr<const meshing::PolyMesh>(vm, &vm->mesh);
    report.set_cache_key("mesh", mesh_key);
  }
  surface.reset();  // the case needs the volume mesh only
#endif
  files.write(dir);
#ifdef BEDFORGE_HAVE_GMSH
  if (!case_reused.is_null()) {
    console.line(fmt::format("case: reused {} (mesh and [case] unchanged)", (dir / "case").string()));
    report.set_stage("case", case_reused);
  } else if (scene.wants("case")) {
    add_case(*mesh, pack.bed, scene.case_params, prov, read_file(dir / "scene.toml"),
             scene.case_params.snappy ? read_file(dir / "fluid.stl") : std::string(), dir, opt.overwrite, report,
             console);
    report.set_cache_key("case", case_key);
  }
#endif
  report.save(dir);
  return 0;
}

// Scene overrides from the command line, applied in the order given.
struct Overrides {
  std::optional<double> aspect_ratio, container_diameter_m, inner_aspect_ratio, box_size_d, diameter_m, eps0,
      stiffness_step, tolerance, temperature;
  std::optional<long long> count, seed, max_iterations, shakes, settling_cycles, mixing_cycles;
  std::optional<std::string> mode, algorithm, container;
  bool periodic = false;

  void add_to(CLI::App& cmd) {
    cmd.add_option("--algorithm", algorithm,
                   "soft-sphere|monte-carlo, packing algorithm (sets packing.algorithm); default soft-sphere");
    cmd.add_option("--container", container, "cylinder|annulus|box (sets container.type); default cylinder");
    cmd.add_option("--inner-aspect-ratio", inner_aspect_ratio,
                   "FLOAT, annulus inner diameter in particle diameters (sets container.inner_diameter_d); no default");
    cmd.add_option("--box-size-d", box_size_d,
                   "FLOAT, box side in particle diameters, both sides (sets container.size_x_d and size_y_d); no "
                   "default");
    cmd.add_flag("--periodic", periodic, "box with periodic sides (sets container.periodic_x and periodic_y)");
    cmd.add_option("--temperature", temperature,
                   "FLOAT > 0, Monte Carlo kT / (m* g d) (sets packing.monte_carlo.temperature); default 0.01");
    cmd.add_option("--shakes", shakes,
                   "INT >= 0, Monte Carlo shakes (sets packing.monte_carlo.shakes); default 10 for equal spheres, "
                   "100 for mixtures");
    cmd.add_option("--mixing-cycles", mixing_cycles,
                   "INT >= 0, Monte Carlo cycles without gravity (sets packing.monte_carlo.mixing_cycles); default 10000");
    cmd.add_option("--settling-cycles", settling_cycles,
                   "INT >= 0, Monte Carlo cycles after the shakes (sets packing.monte_carlo.settling_cycles); default "
                   "100000");
    cmd.add_option("--aspect-ratio", aspect_ratio,
                   "FLOAT, container diameter in particle diameters D/d (sets container.diameter_d); no default");
    cmd.add_option("--container-diameter-m", container_diameter_m,
                   "FLOAT, container diameter in metres (sets container.diameter_m); no default");
    cmd.add_option("--count", count, "INT, number of spheres (sets particles.count); no default");
    cmd.add_option("--diameter-m", diameter_m,
                   "FLOAT, sphere diameter in metres, equal spheres (sets particles.diameter_m); default 0.001");
    cmd.add_option("--seed", seed, "INT >= 0, random seed (sets packing.seed); default 1");
    cmd.add_option("--mode", mode,
                   "accelerated|faithful, soft-sphere schedule (sets packing.soft_sphere.mode); default accelerated");
    cmd.add_option("--initial-void-fraction", eps0,
                   "FLOAT in (0,1), eps_0 of the generation stage (sets packing.soft_sphere.initial_void_fraction); "
                   "default 0.47");
    cmd.add_option("--stiffness-step", stiffness_step,
                   "FLOAT > 0, C_k of Eq. (4), faithful mode (sets packing.soft_sphere.stiffness_step); default 0.3");
    cmd.add_option("--overlap-tolerance-d", tolerance,
                   "FLOAT, final overlap tolerance in smallest diameters (sets "
                   "packing.soft_sphere.overlap_tolerance_d); default 1e-4");
    cmd.add_option("--max-iterations", max_iterations,
                   "INT, iteration cap over all stages (sets packing.soft_sphere.max_iterations); default 5000000");
  }
  void apply(toml::table& t) const {
    if (algorithm) override_key(t, "packing.algorithm", *algorithm);
    if (container) override_key(t, "container.type", *container);
    if (inner_aspect_ratio) override_key(t, "container.inner_diameter_d", *inner_aspect_ratio);
    if (box_size_d) {
      override_key(t, "container.size_x_d", *box_size_d);
      override_key(t, "container.size_y_d", *box_size_d);
    }
    if (periodic) {
      override_key(t, "container.periodic_x", true);
      override_key(t, "container.periodic_y", true);
    }
    if (temperature) override_key(t, "packing.monte_carlo.temperature", *temperature);
    if (shakes) override_key(t, "packing.monte_carlo.shakes", *shakes);
    if (mixing_cycles) override_key(t, "packing.monte_carlo.mixing_cycles", *mixing_cycles);
    if (settling_cycles) override_key(t, "packing.monte_carlo.settling_cycles", *settling_cycles);
    if (aspect_ratio) override_key(t, "container.diameter_d", *aspect_ratio);
    if (container_diameter_m) override_key(t, "container.diameter_m", *container_diameter_m);
    if (count) override_key(t, "particles.count", *count);
    if (diameter_m) override_key(t, "particles.diameter_m", *diameter_m);
    if (seed) override_key(t, "packing.seed", *seed);
    if (mode) override_key(t, "packing.soft_sphere.mode", *mode);
    if (eps0) override_key(t, "packing.soft_sphere.initial_void_fraction", *eps0);
    if (stiffness_step) override_key(t, "packing.soft_sphere.stiffness_step", *stiffness_step);
    if (tolerance) override_key(t, "packing.soft_sphere.overlap_tolerance_d", *tolerance);
    if (max_iterations) override_key(t, "packing.soft_sphere.max_iterations", *max_iterations);
  }
};

toml::table load_table(const std::string& scene_file) {
  if (scene_file.empty()) return {};
  return parse_scene_text(read_file(scene_file), scene_file);
}

}  // namespace

int run_command_line(int argc, char** argv) {
  CLI::App app{fmt::format("bedforge {}: packed beds of spheres, from a scene file to analysed positions.\n"
                           "Exit status: 0 done, 2 bad input, 3 did not converge, 1 internal error.",
                           kVersion),
               "bedforge"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(kVersion));
  Console console;
  bool no_progress = false;
  app.add_flag("--quiet", console.quiet, "print no summary lines");
  app.add_flag("--no-progress", no_progress, "no progress line even on a terminal (default: shown on a terminal, "
                                             "never when CI is set)");

  std::string dir, scene_file;
  Overrides overrides;

  CLI::App* run = app.add_subcommand("run", "run the stages a scene's [outputs] need; writes into -o DIR");
  run->add_option("scene", scene_file, "TOML scene file")->required();
  run->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  bool overwrite = false, force = false;
  run->add_flag("--overwrite", overwrite, "replace DIR/case when the scene asks for a case and it exists");
  const char* force_help =
      "redo every stage; otherwise a stage whose inputs are unchanged (its scene sections, the stage before it and "
      "the bedforge version) is reused from DIR";
  run->add_flag("--force", force, force_help);
  overrides.add_to(*run);

  CLI::App* pack = app.add_subcommand("pack", "pack spheres: writes DIR/bed.csv, bed.vtp, scene.toml, report.json");
  pack->add_option("--scene", scene_file, "TOML scene file to start from; options below override it");
  pack->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  pack->add_flag("--force", force, force_help);
  overrides.add_to(*pack);

  std::string import_file, units = "m", format = "xyzd";
  std::vector<double> origin;
  CLI::App* imp = app.add_subcommand("import", "bring in a bed made elsewhere (a DEM code's output), like pack");
  imp->add_option("file", import_file, "the bed file, in the format --format names")->required();
  imp->add_option("--format", format,
                  "xyzd|lammps-dump|yade: rows x y z d; a LAMMPS/LIGGGHTS text dump (last snapshot, columns x y z "
                  "and radius or diameter); Yade's export.text (x y z r); default xyzd");
  imp->add_option("--units", units, "m|cm|mm|um, length unit of the file; default m");
  imp->add_option("--origin-m", origin,
                  "FLOAT FLOAT FLOAT, metres: the point of the file's frame on the container axis at the floor, moved "
                  "to bedforge's origin; default 0 0 0")
      ->expected(3);
  imp->add_option("--scene", scene_file, "TOML scene file for [container] and [analysis]");
  imp->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  overrides.add_to(*imp);

  CLI::App* analyse = app.add_subcommand("analyse", "analyse DIR/bed.csv: profiles, contacts; adds to DIR/report.json");
  analyse->alias("analyze");
  analyse->add_option("dir", dir, "directory holding bed.csv (as written by pack or import)")->required();
  std::optional<double> exclude_d, radial_bin_d, axial_bin_d, contact_tolerance_d;
  analyse->add_option("--exclude-d", exclude_d,
                      "FLOAT >= 0, diameters left out at floor and top for central values; default 2");
  analyse->add_option("--radial-bin-d", radial_bin_d, "FLOAT > 0, radial bin width in diameters; default 0.05");
  analyse->add_option("--axial-bin-d", axial_bin_d, "FLOAT > 0, axial bin height in diameters; default 0.05");
  analyse->add_option("--contact-tolerance-d", contact_tolerance_d,
                      "FLOAT >= 0, largest gap counted as a contact, in smallest diameters; default 1e-4");

#ifdef BEDFORGE_HAVE_CGAL
  CLI::App* surface = app.add_subcommand("surface", "treat contacts and build the fluid-domain surface of DIR/bed.csv: "
                                                    "writes fluid.stl (a named solid per patch), fluid_PATCH.stl, bed.stl, fluid.vtp");
  surface->add_option("dir", dir, "directory holding bed.csv (as written by pack or import)")->required();
  std::optional<std::string> treatment, wall_treatment;
  std::optional<double> shrink_factor, enlarge_factor, bridge_diameter_d, bridge_gap_d, cap_gap_d, edge_length_d,
      contact_edge_length_d, inlet_length_d, outlet_length_d, min_angle_deg, cells_per_gap;
  surface->add_option("--contacts", treatment,
                      "bridge|cap|shrink|enlarge|none, contact treatment (sets contacts.treatment); default shrink");
  surface->add_option("--wall-contacts", wall_treatment,
                      "same|bridge|cap|none, treatment of sphere-wall contacts (sets contacts.wall_treatment); "
                      "default same");
  surface->add_option("--shrink-factor", shrink_factor,
                      "FLOAT in [0.5,1), sphere scale for shrink (sets contacts.shrink_factor); default 0.99");
  surface->add_option("--enlarge-factor", enlarge_factor,
                      "FLOAT in (1,1.2], sphere scale for enlarge (sets contacts.enlarge_factor); default 1.01");
  surface->add_option("--bridge-diameter-d", bridge_diameter_d,
                      "FLOAT in (0,0.8), bridge diameter in diameters (sets contacts.bridge_diameter_d); default 0.2");
  surface->add_option("--bridge-gap-d", bridge_gap_d,
                      "FLOAT in [0,0.5], gaps below this get a bridge, in diameters (sets contacts.bridge_gap_d); "
                      "default 0.01");
  surface->add_option("--cap-gap-d", cap_gap_d,
                      "FLOAT in (0,0.2], gap caps leave, in diameters (sets contacts.cap_gap_d); default 0.02");
  surface->add_option("--edge-length-d", edge_length_d,
                      "FLOAT in [0.001,1], target triangle edge in diameters (sets surface.edge_length_d); default 0.1");
  surface->add_option("--contact-edge-length-d", contact_edge_length_d,
                      "FLOAT in [0.001,1], edge where treated contacts meet, in diameters (sets "
                      "surface.contact_edge_length_d); default 0.033");
  surface->add_option("--cells-per-gap", cells_per_gap,
                      "FLOAT in [0,20], cells across narrow gaps: edges shrink to gap / this where a surface faces "
                      "another closer than this x the edge length, not below the contact edge; 0 for none (sets "
                      "surface.cells_per_gap); default 0");
  surface->add_option("--min-angle-deg", min_angle_deg,
                      "FLOAT in [0,30], quality gate: smallest triangle angle allowed in degrees, else the stage fails "
                      "and writes bad_triangles.vtp (sets surface.min_angle_deg); default 2");
  surface->add_option("--inlet-length-d", inlet_length_d,
                      "FLOAT >= 0, empty section below the bed in diameters (sets surface.inlet_length_d); default 1");
  surface->add_option("--outlet-length-d", outlet_length_d,
                      "FLOAT >= 0, empty section above the bed in diameters (sets surface.outlet_length_d); default 1");
  std::vector<double> clip_window_d;
  surface->add_option("--clip-window-d", clip_window_d,
                      "FLOAT FLOAT, heights above the floor in diameters whose planes become the inlet and outlet, "
                      "cutting the spheres there, instead of the empty sections (sets surface.clip_window_d); "
                      "default none")
      ->expected(2);

  CLI::App* case_cmd = app.add_subcommand("case", "write the OpenFOAM case DIR/case from DIR/fluid.msh (simpleFoam, "
                                                  "laminar); run it with DIR/case/Allrun [-np N]");
  case_cmd->add_option("dir", dir, "directory holding fluid.msh (as written by mesh)")->required();
  std::optional<double> reynolds;
  std::optional<long long> processors, iterations;
  std::optional<std::string> case_format, run_mesh;
  bool run_flow = false, snappy = false;
  case_cmd->add_option("--reynolds", reynolds,
                       "FLOAT in (0,1000], particle Reynolds number of the superficial velocity (sets case.reynolds); "
                       "default 1");
  case_cmd->add_option("--iterations", iterations, "INT >= 1, simpleFoam iteration cap (sets case.iterations); default 3000");
  case_cmd->add_option("--processors", processors,
                       "INT >= 1, subdomains in decomposeParDict (sets case.processors); default 1");
  case_cmd->add_option("--format", case_format, "binary|ascii, polyMesh and field format (sets case.format); default binary");
  case_cmd->add_flag("--snappy", snappy, "also write the snappyHexMesh set-up, used by Allrun -snappy (sets case.snappy)");
  case_cmd->add_flag("--run", run_flow, "run Allrun and add the pressure drop to the report (sets case.run)");
  case_cmd->add_option("--run-mesh", run_mesh,
                       "gmsh|snappy, the mesh --run solves on: gmsh's, or snappyHexMesh's made first by Allrun "
                       "-snappy (needs --snappy; sets case.run_mesh); default gmsh");
  case_cmd->add_flag("--overwrite", overwrite, "replace DIR/case when it exists");
#endif
#ifdef BEDFORGE_HAVE_GMSH
  CLI::App* mesh_cmd = app.add_subcommand("mesh", "mesh the fluid domain of DIR/fluid.stl with gmsh, held to the quality "
                                                  "gate: writes DIR/fluid.msh (bad_cells.vtk when the gate fails)");
  mesh_cmd->add_option("dir", dir, "directory holding fluid.stl and bed.csv (as written by surface)")->required();
  std::optional<std::string> mesh_algorithm;
  std::optional<double> max_size_d, max_non_orthogonality, layer_thickness_d;
  std::optional<int> layers;
  mesh_cmd->add_option("--algorithm", mesh_algorithm,
                       "hxt|delaunay, first 3D algorithm tried, the other is the fallback (sets mesh.algorithm); "
                       "default hxt");
  mesh_cmd->add_option("--max-size-d", max_size_d,
                       "FLOAT in [0.01,10], largest cell edge in diameters (sets mesh.max_size_d); default 0.25");
  mesh_cmd->add_option("--max-non-orthogonality", max_non_orthogonality,
                       "FLOAT in (0,90), quality gate in degrees (sets mesh.gate.max_non_orthogonality_deg); default 85");
  mesh_cmd->add_option("--layers", layers,
                       "INT in [0,20], prism layers on the particle surfaces (sets mesh.layers.count); default 0");
  mesh_cmd->add_option("--layer-thickness-d", layer_thickness_d,
                       "FLOAT in (0,0.5), total thickness of the prism layers in diameters where the gaps allow it "
                       "(sets mesh.layers.thickness_d); default 0.02");
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (no_progress) console.progress = false;

  if (*run || *pack || *imp) {
    toml::table table = load_table(scene_file);
    if (*imp) {
      override_key(table, "packing.algorithm", std::string("import"));
      override_key(table, "packing.file", std::filesystem::absolute(import_file).string());
      override_key(table, "packing.units", units);
      override_key(table, "packing.format", format);
      if (!origin.empty()) override_key(table, "packing.origin_m", toml::array{origin[0], origin[1], origin[2]});
    }
    overrides.apply(table);
    const Scene scene = read_scene(table, scene_file.empty() ? "command line" : scene_file,
                                   scene_file.empty() ? fs::path() : fs::path(scene_file).parent_path());
    if (*run) return run_scene(scene, dir, {scene.wants("analysis"), scene.wants("positions"), overwrite, force}, console);
    return run_scene(scene, dir, {false, true, false, force}, console);
  }

  // analyse, surface, mesh or case on DIR
  const fs::path d(dir);
  ImportedBed in = read_bed_text(d / "bed.csv", 1.0);
  if (!in.bed.container)
    throw InputError(fmt::format("{}: the header names no container; write the bed with `bedforge import`",
                                 (d / "bed.csv").string()));
  toml::table table;
  if (fs::exists(d / "scene.toml")) table = parse_scene_text(read_file(d / "scene.toml"), (d / "scene.toml").string());
  if (exclude_d) override_key(table, "analysis.exclude_d", *exclude_d);
  if (radial_bin_d) override_key(table, "analysis.radial_bin_d", *radial_bin_d);
  if (axial_bin_d) override_key(table, "analysis.axial_bin_d", *axial_bin_d);
  if (contact_tolerance_d) override_key(table, "analysis.contact_tolerance_d", *contact_tolerance_d);
  Report report = Report::load_or_new(d);
  Outputs files;
#ifdef BEDFORGE_HAVE_CGAL
  if (*surface) {
    if (treatment) override_key(table, "contacts.treatment", *treatment);
    if (wall_treatment) override_key(table, "contacts.wall_treatment", *wall_treatment);
    if (shrink_factor) override_key(table, "contacts.shrink_factor", *shrink_factor);
    if (enlarge_factor) override_key(table, "contacts.enlarge_factor", *enlarge_factor);
    if (bridge_diameter_d) override_key(table, "contacts.bridge_diameter_d", *bridge_diameter_d);
    if (bridge_gap_d) override_key(table, "contacts.bridge_gap_d", *bridge_gap_d);
    if (cap_gap_d) override_key(table, "contacts.cap_gap_d", *cap_gap_d);
    if (edge_length_d) override_key(table, "surface.edge_length_d", *edge_length_d);
    if (contact_edge_length_d) override_key(table, "surface.contact_edge_length_d", *contact_edge_length_d);
    if (cells_per_gap) override_key(table, "surface.cells_per_gap", *cells_per_gap);
    if (min_angle_deg) override_key(table, "surface.min_angle_deg", *min_angle_deg);
    if (inlet_length_d) override_key(table, "surface.inlet_length_d", *inlet_length_d);
    if (outlet_length_d) override_key(table, "surface.outlet_length_d", *outlet_length_d);
    if (!clip_window_d.empty()) {
      override_key(table, "surface.clip_window_d", toml::array{clip_window_d[0], clip_window_d[1]});
      // The bed's scene may give empty sections; a window given here replaces them.
      if (auto* s = table["surface"].as_table()) {
        if (!inlet_length_d) s->erase("inlet_length_d");
        if (!outlet_length_d) s->erase("outlet_length_d");
      }
    }
    SceneSection contacts(table["contacts"].as_table(), "contacts"), surf(table["surface"].as_table(), "surface");
    const meshing::SurfaceParams params = meshing::read_surface_params(contacts, surf);
    contacts.finish();
    surf.finish();
    add_surface(in.bed, params, kVersion, true, d, report, files, console);
    files.write(d);
    report.save(d);
    return 0;
  }
  if (*case_cmd) {
    if (reynolds) override_key(table, "case.reynolds", *reynolds);
    if (iterations) override_key(table, "case.iterations", *iterations);
    if (processors) override_key(table, "case.processors", *processors);
    if (case_format) override_key(table, "case.format", *case_format);
    if (snappy) override_key(table, "case.snappy", true);
    if (run_flow) override_key(table, "case.run", true);
    if (run_mesh) override_key(table, "case.run_mesh", *run_mesh);
    SceneSection section(table["case"].as_table(), "case");
    const cases::CaseParams params = cases::read_case_params(section);
    section.finish();
#ifdef BEDFORGE_HAVE_GMSH
    const meshing::PolyMesh mesh = meshing::read_msh(d / "fluid.msh");
#else
    throw InputError("this bedforge was built without gmsh and cannot read DIR/fluid.msh; install libgmsh-dev and rebuild");
#endif
    const Provenance prov{kVersion, report.data().value("seed", 0ULL), report.data().value("scene", nlohmann::json())};
    add_case(mesh, in.bed, params, prov,
             scene_to_toml(table), params.snappy ? read_file(d / "fluid.stl") : std::string(), d, overwrite, report,
             console);
    report.save(d);
    return 0;
  }
#endif
#ifdef BEDFORGE_HAVE_GMSH
  if (*mesh_cmd) {
    if (mesh_algorithm) override_key(table, "mesh.algorithm", *mesh_algorithm);
    if (max_size_d) override_key(table, "mesh.max_size_d", *max_size_d);
    if (max_non_orthogonality) override_key(table, "mesh.gate.max_non_orthogonality_deg", *max_non_orthogonality);
    if (layers) override_key(table, "mesh.layers.count", static_cast<long long>(*layers));
    if (layer_thickness_d) override_key(table, "mesh.layers.thickness_d", *layer_thickness_d);
    SceneSection section(table["mesh"].as_table(), "mesh");
    const meshing::VolumeMeshParams params = meshing::read_volume_mesh_params(section);
    section.finish();
    const meshing::TriangleMesh surface =
        meshing::read_stl_ascii_by_patch(read_file(d / "fluid.stl"), (d / "fluid.stl").string());
    // A surface edited or made elsewhere: gmsh needs it closed, so say where it is not.
    const meshing::SurfaceCheck check = meshing::check_surface(surface, 0);
    if (!check.closed || !check.manifold) {
      const std::string where = meshing::describe_defects(check);
      throw InputError(fmt::format("{}: the surface is not closed ({} defective edges, first at{}); a volume needs a "
                                   "closed surface: rebuild it with `bedforge surface`",
                                   (d / "fluid.stl").string(), check.defects.size(), where));
    }
    const nlohmann::json& stage = report.data().contains("stages") ? report.data()["stages"] : nlohmann::json();
    double exact = std::numeric_limits<double>::quiet_NaN();
    if (stage.contains("surface") && stage["surface"].contains("fluid_volume_exact_m3"))
      exact = stage["surface"]["fluid_volume_exact_m3"].get<double>();
    add_mesh(surface, exact, in.bed, params, true, d, report, files, console);
    files.write(d);
    report.save(d);
    return 0;
  }
#endif
  SceneSection section(table["analysis"].as_table(), "analysis");
  const analysis::AnalysisParams params = analysis::read_analysis_params(section);
  section.finish();
  add_analysis(in.bed, params, report, files, console);
  files.write(d);
  report.save(d);
  return 0;
}

}  // namespace bedforge
