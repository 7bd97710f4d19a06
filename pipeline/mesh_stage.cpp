#include "pipeline/mesh_stage.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "meshing/surface/fluid_surface.hpp"

namespace bedforge::pipeline {

MeshStage mesh_stage(const meshing::TriangleMesh& surface, double exact_volume_m3, const Bed& bed,
                     const meshing::SurfaceParams& surface_params, const meshing::VolumeMeshParams& p,
                     const std::filesystem::path& msh_path,
                     const std::filesystem::path& bad_cells_path, const Console& console) {
  const StageMeter meter;
  std::filesystem::create_directories(bad_cells_path.parent_path());
  Progress progress("mesh", console.progress);
  const int slabs = meshing::slab_count(surface.triangles.size(), surface_params, p, *bed.container);
  auto vm = std::make_shared<meshing::VolumeMesh>(
      slabs > 1 ? meshing::build_slabbed_volume_mesh(bed, surface_params, &surface, slabs, reference_diameter(bed), p,
                                                     msh_path, bad_cells_path, progress)
                : meshing::build_volume_mesh(surface, bed, reference_diameter(bed), p, msh_path, bad_cells_path, progress));
  progress.finish();
  MeshStage out{vm, std::move(vm->report)};
  nlohmann::json& j = out.report;
  const meshing::CellQuality& q = vm->quality;
  const double volume_error = (q.total_volume - exact_volume_m3) / exact_volume_m3;
  j["parameters"] = meshing::to_json(p);
  j["fluid_volume_exact_m3"] = exact_volume_m3;
  j["fluid_volume_relative_error"] = volume_error;
  std::string line = fmt::format(
      "mesh ({}{}): {} cells, max non-orthogonality {:.1f} deg (mean {:.1f}, {} faces > 70), max skewness {:.2f}, "
      "max aspect ratio {:.1f}, volume error {:.2e}",
      j["algorithm"].get<std::string>(),
      std::string(j["optimiser"] == "hxt" ? ", its own optimiser" : "") +
          (slabs > 1 ? fmt::format(", {} slabs", slabs) : std::string()) +
          (j.contains("planes_moved") ? fmt::format(" between planes moved to {:.3f} d as the first failed (the "
                                                    "report's planes_moved says why)",
                                                    fmt::join(j["planes_moved"]["to_d"].get<std::vector<double>>(), ", "))
                                      : std::string()),
      vm->mesh.cells,
      q.max_non_orthogonality_deg, q.mean_non_orthogonality_deg, q.faces_over_70_deg, q.max_skewness,
      q.max_aspect_ratio, volume_error);
  if (j.contains("layers")) {
    const auto& l = j["layers"];
    line += fmt::format("; {} prism layers, mean thickness {:.3g} d, {} of {} stacks at full thickness",
                        p.layers.count, l["mean_thickness_d"].get<double>(), l["stacks_at_full_thickness"].get<long>(),
                        l["stacks"].get<long>());
  }
  finish_stage(j, meter, line, console);
  return out;
}

namespace {

constexpr double kDensestVoidFraction = 0.36;
// simpleFoam's two processes held together 897 and 1038 bytes per tetrahedron on the polyhedral
// dual (2026-11-28, docs/findings.md); on the tetrahedra themselves, whose gradients are fitted
// over the cells sharing a vertex, twice the largest process's 3.4-3.5 kB per tetrahedron (2.94 M
// and 5.97 M, 2026-12-04 and 2026-12-03, docs/findings.md): as much as the mesh stage or more.
constexpr double kSolverBytesPerCellDual = 850.0, kSolverBytesPerCellTetrahedra = 3300.0;

MeshEstimate with_cells(const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                        const cases::CaseParams& c, const meshing::FluidDomainSize& fluid, double d,
                        const Container& container) {
  const bool in_slabs = meshing::meshes_in_slabs(surface, mesh, container);
  const double mesh_bytes = in_slabs ? 300.0 : 460.0;
  const bool solver = c.run && !c.snappy_cells;
  const double h = std::min(surface.edge_length_d, mesh.max_size_d) * d;  // the edge away from the surfaces
  MeshEstimate e;
  e.fluid_volume_m3 = fluid.volume_m3;
  e.gap_cells = fluid.gap_cells;
  // With cells_per_gap, the gaps' cells already hold those graded from the contacts' loops.
  e.contact_cells = surface.cells_per_gap > 0.0
                        ? 0.0
                        : kCellsPerContactLoopEdge * fluid.contact_loop_edges +
                              kCellsPerThinGapContact / surface.edge_length_d * fluid.thin_gap_contacts;
  e.cells = fluid.volume_m3 / (kEstimateVolumePerCell * h * h * h) + e.gap_cells + e.contact_cells;
  e.mesh_peak_bytes = e.cells * mesh_bytes;
  e.likely_mesh_peak_bytes = e.gap_cells > 0.0 ? e.cells * kGapsRefinedBytesPerCell : e.mesh_peak_bytes;
  const double solver_bytes = c.polyhedra ? kSolverBytesPerCellDual : kSolverBytesPerCellTetrahedra;
  e.peak_bytes = solver ? e.cells * solver_bytes : e.mesh_peak_bytes;
  e.peak_in_solver = solver;
  return e;
}

// The part of e.cells the bed's narrow gaps or contacts add, in parentheses ("" when none);
// `of_them` goes after the count.
std::string added_cells(const MeshEstimate& e, const char* of_them) {
  if (e.gap_cells > 0.0) return fmt::format(" ({:.3g} million{} across the bed's narrow gaps)", e.gap_cells / 1e6, of_them);
  if (e.contact_cells > 0.0) return fmt::format(" ({:.3g} million{} around its contacts)", e.contact_cells / 1e6, of_them);
  return {};
}

std::string beyond_memory(const MeshEstimate& e, double available_bytes) {
  const std::string gaps = added_cells(e, " of them");
  return fmt::format("the volume mesh would take at least {:.3g} million cells{} and {:.1f} GB in {} (an estimate "
                     "that errs low), and this machine has {:.1f} GB available",
                     e.cells / 1e6, gaps, e.peak_bytes / 1e9,
                     e.peak_in_solver ? "simpleFoam's processes together" : "the mesh stage", available_bytes / 1e9);
}

// What else would fit when the solver sets the peak: the case written, to run elsewhere.
std::string or_not_run(const MeshEstimate& e) { return e.peak_in_solver ? ", case.run = false" : ""; }

void refuse_edge(const Scene& scene, const MeshEstimate& e, double available_bytes) {
  // Cells scale with h^-3, so the edge that would fit is this one times the cube root of the excess.
  // (Cells graded around contacts do not: a longer contact edge has fewer.)
  const double fits = scene.surface.edge_length_d * std::cbrt(e.peak_bytes / available_bytes);
  const std::string contacts =
      e.contact_cells > 0.0 ? fmt::format(", a longer surface.contact_edge_length_d (now {})",
                                          scene.surface.contact_edge_length_d)
                            : std::string();
  throw InputError(fmt::format("surface.edge_length_d = {}: {}; allowed: surface.edge_length_d >= {:.3g}{}, fewer "
                               "spheres, a clip window (surface.clip_window_d){}",
                               scene.surface.edge_length_d, beyond_memory(e, available_bytes), fits, contacts,
                               or_not_run(e)));
}

}  // namespace

MeshEstimate estimate_mesh(const Scene& scene) {
  double d = 0.0, solid = 0.0;
  if (scene.import.bed) {
    const Bed& b = scene.import.bed->bed;
    d = reference_diameter(b);  // an imported empty container keeps its own
    solid = solid_volume(b);
  } else {
    d = scene.sizes.sauter_mean();
    solid = static_cast<double>(scene.count) * scene.sizes.mean_volume();
  }
  const double area = scene.container->cross_section_area();
  const meshing::SurfaceParams& s = scene.surface;
  double fluid = 0.0;
  if (s.clip) {
    fluid = area * (s.clip_top_d - s.clip_bottom_d) * d * kDensestVoidFraction;
  } else {
    const double bed_height = solid / (area * (1.0 - kDensestVoidFraction));
    fluid = area * (bed_height + (s.inlet_length_d + s.outlet_length_d) * d) - solid;
  }
  return with_cells(scene.surface, scene.mesh, scene.case_params, {fluid, 0.0, 0.0, 0.0}, d, *scene.container);
}

MeshEstimate estimate_mesh(const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, const meshing::FluidDomainSize& fluid, double d,
                           const Container& container) {
  return with_cells(surface, mesh, case_params, fluid, d, container);
}

MeshEstimate estimate_mesh(const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, const Bed& bed) {
  return estimate_mesh(surface, mesh, case_params,
                       meshing::fluid_domain_profile(bed, surface, kEstimateVolumePerCell, 1).size,
                       reference_diameter(bed), *bed.container);
}

MeshEstimate estimate_mesh(const Scene& scene, const Bed& bed) {
  return estimate_mesh(scene.surface, scene.mesh, scene.case_params, bed);
}

std::string estimate_line(const MeshEstimate& e, double available_bytes) {
  const std::string gaps = added_cells(e, "");
  return fmt::format("mesh estimate: at least {:.3g} million cells{}, {:.1f} GB at the peak ({}) of the {:.1f} GB available",
                     e.cells / 1e6, gaps, e.peak_bytes / 1e9, e.peak_in_solver ? "simpleFoam" : "mesh stage",
                     available_bytes / 1e9);
}

nlohmann::json to_json(const MeshEstimate& e) {
  return {{"cells", e.cells}, {"gap_cells", e.gap_cells}, {"contact_cells", e.contact_cells},
          {"peak_memory_mb", e.peak_bytes / 1048576.0}};
}

void refuse_mesh_beyond_memory(const Scene& scene, double available_bytes) {
  const MeshEstimate e = estimate_mesh(scene);
  if (e.peak_bytes > available_bytes) refuse_edge(scene, e, available_bytes);
}

MeshEstimate refuse_mesh_beyond_memory(const Scene& scene, const Bed& bed, double available_bytes) {
  const MeshEstimate e = estimate_mesh(scene, bed);
  if (e.peak_bytes <= available_bytes) return e;
  const double bulk_bytes = e.peak_bytes * (1.0 - e.gap_cells / e.cells);
  if (e.gap_cells == 0.0 || bulk_bytes > 0.5 * available_bytes) refuse_edge(scene, e, available_bytes);
  // The gaps' cells grow about as cells_per_gap^2 / contact edge (a refined patch's cells go as
  // cells_per_gap^3 over the gap squared, summed over gaps down to cells_per_gap x contact edge).
  const meshing::SurfaceParams& s = scene.surface;
  const double excess = (e.peak_bytes - bulk_bytes) / (available_bytes - bulk_bytes);
  throw InputError(fmt::format(
      "surface.cells_per_gap = {} with surface.contact_edge_length_d = {}: {}; allowed: surface.cells_per_gap <= about "
      "{:.2g}, surface.contact_edge_length_d >= about {:.2g}, a clip window (surface.clip_window_d){}",
      s.cells_per_gap, s.contact_edge_length_d, beyond_memory(e, available_bytes), s.cells_per_gap / std::sqrt(excess), s.contact_edge_length_d * excess, or_not_run(e)));
}

void refuse_piece_beyond_memory(const MeshEstimate& e, const meshing::SurfaceParams& s, int piece, int pieces,
                                int ranks_here, double available_bytes) {
  const double need = e.likely_mesh_peak_bytes;
  if (need <= available_bytes) return;
  const bool measured = e.gap_cells > 0.0;
  throw InputError(fmt::format(
      "mesh.pieces = {}: piece {} would take {} {:.1f} GB to mesh ({:.3g} million cells, {}), and a rank may "
      "take {:.1f} GB here ({} rank{} on this machine sharing its memory); allowed: {}",
      pieces, piece + 1, measured ? "about" : "at least", need / 1e9, e.cells / 1e6, piece_memory_basis(measured),
      available_bytes / 1e9, ranks_here, ranks_here == 1 ? "" : "s",
      pieces_memory_remedies(fmt::format("mesh.pieces >= {}", static_cast<int>(std::ceil(pieces * need / available_bytes)))) +
          // A longer edge hardly changes the cells across narrow gaps (8.95 M at 0.2 d, 8.98 M at
          // 0.15 d on the same piece), so say what does when they are most of the piece.
          (e.gap_cells > 0.5 * e.cells
               ? fmt::format(" (the narrow gaps hold {:.0f} % of its cells: {})", 100.0 * e.gap_cells / e.cells, gaps_remedy(s))
               : std::string())));
}

std::string piece_memory_basis(bool gaps_refined) {
  return gaps_refined ? fmt::format("{:.0f} bytes per estimated cell, as measured with the gaps refined",
                                    kGapsRefinedBytesPerCell)
                      : "an estimate that errs low";
}

std::string pieces_memory_remedies(const std::string& more_pieces) {
  return more_pieces + " (with as many ranks, spread over machines), fewer ranks per machine, or a longer "
                       "surface.edge_length_d";
}

std::string gaps_remedy(const meshing::SurfaceParams& s) {
  return fmt::format("fewer surface.cells_per_gap, now {}, or a longer surface.contact_edge_length_d, now {}",
                     s.cells_per_gap, s.contact_edge_length_d);
}

}  // namespace bedforge::pipeline
