#include "pipeline/directory_stages.hpp"

#include <fmt/format.h>

#include <cstdlib>

#include <limits>
#include <optional>
#include <string>

#include "core/atomic_file.hpp"
#include "core/bed_io.hpp"
#include "core/error.hpp"
#include "core/report.hpp"
#include "core/version.hpp"
#include "pipeline/analysis_stage.hpp"
#include "pipeline/output_files.hpp"
#include "meshing/surface/stl_io.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "meshing/surface/surface_checks.hpp"
#include "pipeline/surface_stage.hpp"
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
#include "pipeline/convergence_study.hpp"
#include "pipeline/mesh_stage.hpp"
#include "pipeline/piece_stage.hpp"
#include "core/stage_meter.hpp"
#endif
#ifdef BEDFORGE_HAVE_GMSH
#include "meshing/volume/gmsh_model.hpp"
#include "pipeline/case_stage.hpp"
#endif

namespace bedforge::pipeline {

namespace fs = std::filesystem;

namespace {

// What a stage run on its own starts from: the bed, the scene as run with the overrides, and
// the report the earlier stages left.
struct Directory {
  Bed bed;
  nlohmann::json bed_header;  // bed.csv's {"version", "seed", "scene"}
  toml::table scene;
  Report report;
};

Directory open_directory(const fs::path& dir, const std::vector<Override>& overrides) {
  Directory d;
  ImportedBed read = read_bed_text(dir / "bed.csv", 1.0);
  d.bed = std::move(read.bed);
  d.bed_header = std::move(read.header);
  if (!d.bed.container)
    throw InputError(fmt::format("{}: the header names no container; write the bed with `bedforge import`",
                                 (dir / "bed.csv").string()));
  if (fs::exists(dir / "scene.toml"))
    d.scene = parse_scene_text(read_file(dir / "scene.toml"), (dir / "scene.toml").string());
  apply_overrides(d.scene, overrides);
  d.report = Report::load_or_new(dir);
  return d;
}

// A section's parameters by its reader, every key checked.
template <class Reader>
auto read_section(toml::table& scene, const char* name, Reader reader) {
  SceneSection section(scene[name].as_table(), name);
  auto params = reader(section);
  section.finish();
  return params;
}

#ifdef BEDFORGE_HAVE_CGAL
// The contact treatment and surface settings, sections [contacts] and [surface], every key checked.
meshing::SurfaceParams read_surface_sections(toml::table& scene) {
  SceneSection contacts(scene["contacts"].as_table(), "contacts"), surface(scene["surface"].as_table(), "surface");
  const meshing::SurfaceParams params = meshing::read_surface_params(contacts, surface);
  contacts.finish();
  surface.finish();
  return params;
}
#endif

}  // namespace

void analyse_directory(const fs::path& dir, const std::vector<Override>& overrides, const Console& console) {
  Directory d = open_directory(dir, overrides);
  const analysis::AnalysisParams params = read_section(d.scene, "analysis", analysis::read_analysis_params);
  AnalysisStage a = analysis_stage(d.bed, params, console);
  OutputFiles files;
  for (auto& [name, csv] : a.csv_files) files.add(name, std::move(csv));
  d.report.set_stage("analysis", std::move(a.report));
  files.write(dir);
  d.report.save(dir);
}

#ifdef BEDFORGE_HAVE_CGAL
void surface_directory(const fs::path& dir, const std::vector<Override>& overrides, const Console& console) {
  Directory d = open_directory(dir, overrides);
  const meshing::SurfaceParams params = read_surface_sections(d.scene);
  SurfaceStage s = surface_stage(d.bed, params, dir / "bad_triangles.vtp", console);
  OutputFiles files;
  add_surface_files(s.surface, files);
  d.report.set_stage("surface", std::move(s.report));
  files.write(dir);
  d.report.save(dir);
}
#endif

#ifdef BEDFORGE_HAVE_VOLUME_MESH
void mesh_directory(const fs::path& dir, const std::vector<Override>& overrides, const Console& console) {
  Directory d = open_directory(dir, overrides);
  meshing::VolumeMeshParams params = read_section(d.scene, "mesh", meshing::read_volume_mesh_params);
  // The finest level of the study `bedforge case DIR` will make, layered as its coarsest.
  params.layers = layers_for_study(params.layers, read_section(d.scene, "case", cases::read_case_params).convergence);
  // Slabs are surfaces built again from the bed; here the surface is fluid.stl as it is.
  if (params.slabs > 1)
    throw InputError(fmt::format("mesh.slabs = {}: `bedforge mesh DIR` meshes DIR/fluid.stl as it is, in one piece; "
                                 "allowed: 0 or 1 here, or slabs through `bedforge run`",
                                 params.slabs));
  params.slabs = 1;
  const fs::path stl = dir / "fluid.stl";
  const meshing::TriangleMesh surface = meshing::read_stl_ascii_by_patch(stl);
  // A surface edited or made elsewhere: gmsh needs it closed, so say where it is not.
  const meshing::SurfaceCheck check = meshing::check_surface(surface, meshing::SelfIntersectionTest::skip);
  if (!check.closed || !check.manifold)
    throw InputError(fmt::format("{}: the surface is not closed ({} defective edges, first at{}); a volume needs a "
                                 "closed surface: rebuild it with `bedforge surface`",
                                 stl.string(), check.defects.size(), meshing::describe_defects(check)));
  // The exact volume is the surface stage's record; a surface made elsewhere has none.
  const nlohmann::json& stages = d.report.data().value("stages", nlohmann::json::object());
  const double exact = stages.contains("surface")
                           ? stages["surface"].value("fluid_volume_exact_m3", std::numeric_limits<double>::quiet_NaN())
                           : std::numeric_limits<double>::quiet_NaN();
  OutputFiles files;
  const fs::path msh = dir / ".fluid.partial.msh";  // gmsh picks the format by extension
  files.add_made("fluid.msh", msh);
  MeshStage m = mesh_stage(surface, exact, d.bed, meshing::SurfaceParams{}, params, msh, dir / "bad_cells.vtk", console);
  d.report.set_stage("mesh", std::move(m.report));
  files.write(dir);
  d.report.save(dir);
}
#endif

#ifdef BEDFORGE_HAVE_VOLUME_MESH
void piece_directory(const fs::path& dir, const std::vector<Override>& overrides, int piece, int pieces,
                     const std::vector<double>& planes_d, double wall_gap_m, const Console& console) {
  Directory d = open_directory(dir, overrides);
  meshing::SurfaceParams surface = read_surface_sections(d.scene);
  const meshing::VolumeMeshParams mesh = read_section(d.scene, "mesh", meshing::read_volume_mesh_params);
  const cases::CaseParams params = read_section(d.scene, "case", cases::read_case_params);
  // Before any meshing: the planes given must lie inside the fluid domain, and this machine's
  // ranks' pieces must fit in its memory. Given the planes and the wall gap (as a run gives
  // them), the rank treats only its piece's window; else it surveys the bed for both first.
  if (!planes_d.empty()) meshing::check_given_planes_d(d.bed, surface, planes_d, pieces, "--planes-d");
  std::vector<double> planes = planes_d;
  if (planes.empty() || !(wall_gap_m > 0.0)) {
    const meshing::SlabPlanes found = meshing::slab_planes(d.bed, surface, pieces);
    if (planes.empty()) planes = found.planes_d;
    if (!(wall_gap_m > 0.0)) wall_gap_m = found.wall_gap_m;
  }
  surface.ring_wall_gap_m = wall_gap_m;
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const MeshEstimate estimate =
      estimate_mesh(surface, mesh, params, meshing::slab_domain_size(d.bed, surface, planes, piece, kEstimateVolumePerCell),
                    reference_diameter(d.bed), *d.bed.container);
  refuse_piece_beyond_memory(estimate, surface, piece, pieces, local ? std::atoi(local) : 1, available_memory_bytes());
  // The seed from bed.csv: a run starts its ranks before it writes report.json.
  const nlohmann::json& seed = d.bed_header.value("seed", nlohmann::json());
  const std::string note = fmt::format("bedforge {}, seed {}, piece {} of {}", kVersion,
                                       seed.is_number() ? std::to_string(seed.get<unsigned long long>()) : "none",
                                       piece, pieces);
  const nlohmann::json r = piece_stage(d.bed, stage_key(read_file(dir / "bed.csv")), surface,
                                       planes,
                                       mesh, params, piece, pieces, dir / "case", note, console);
  // With the estimate beside the cells made and the peak, so that every run tells how far it erred.
  console.line(fmt::format("piece {} of {}: {} cells (estimated {:.3g} million tetrahedra, {:.1f} GB; peak {:.1f} GB) in {}{}",
                           piece + 1, pieces, r["cells"].get<long>(), estimate.cells / 1e6,
                           estimate.likely_mesh_peak_bytes / 1e9, r.value("peak_memory_mb", 0.0) * 1048576.0 / 1e9,
                           (dir / "case" / fmt::format("processor{}", piece)).string(),
                           r.value("reused", false) || r["slab"].value("reused", false)
                               ? " (kept from an earlier run made from the same)"
                               : ""));
}
#endif

#ifdef BEDFORGE_HAVE_GMSH
void case_directory(const fs::path& dir, const std::vector<Override>& overrides, bool overwrite, const Console& console) {
  Directory d = open_directory(dir, overrides);
  const cases::CaseParams params = read_section(d.scene, "case", cases::read_case_params);
#ifndef BEDFORGE_HAVE_VOLUME_MESH
  if (params.convergence.levels > 0)
    throw InputError("case.convergence needs the surface and mesh stages, which this bedforge was built without");
#endif
  // gmsh's cells, or for snappyHexMesh's the surface it meshes.
  const fs::path stl = dir / "fluid.stl";
  std::shared_ptr<const meshing::PolyMesh> mesh;
  std::shared_ptr<const meshing::TriangleMesh> surface;
  if (params.snappy_cells)
    surface = std::make_shared<const meshing::TriangleMesh>(meshing::read_stl_ascii_by_patch(stl));
  else
    mesh = std::make_shared<const meshing::PolyMesh>(meshing::read_msh(dir / "fluid.msh"));
  const Provenance prov{kVersion, d.report.data().value("seed", 0ULL), d.report.data().value("scene", nlohmann::json())};
#ifdef BEDFORGE_HAVE_CGAL
  const cases::TreatedSolid treated = treated_solid(read_surface_sections(d.scene), d.bed);
#else
  const cases::TreatedSolid treated{0.0, 0};  // without a surface stage the treatment is not known
#endif
  const CaseStage c = case_stage(std::move(mesh), std::move(surface), d.bed, params, prov,
                                 scene_to_toml(d.scene), params.snappy ? stl : fs::path(), dir / "case", overwrite,
                                 treated, console);
  nlohmann::json entry = c.report;
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // The coarser levels need the whole scene: their surface and mesh settings, scaled.
  if (params.convergence.levels > 0)
    add_convergence_study(read_scene(d.scene, (dir / "scene.toml").string(), dir), d.bed, finest_level(c, d.report, ""),
                          nullptr, dir, console, entry);
#endif
  d.report.set_stage("case", std::move(entry));
  d.report.save(dir);
}
#endif

}  // namespace bedforge::pipeline
