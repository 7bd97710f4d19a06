#include "pipeline/case_stage.hpp"

#include <fmt/format.h>

#include "core/stage_meter.hpp"

namespace bedforge::pipeline {

namespace {

// Runs the written case `out.info` and adds its flow to `out` and to the stage's `line`.
void run_flow(CaseStage& out, std::string& line, const Console& console) {
  Progress progress("case", console.progress);
  const cases::FlowResult& flow = out.flow.emplace(cases::run_case(out.info, progress));
  out.report["flow"] = flow.to_json();
  if (flow.solved_cells != out.info.cells) line += fmt::format("; solved on {} cells ({})", flow.solved_cells, flow.mesher);
  if (flow.volume_lost) line += fmt::format(", {:.1f} % of the surface's fluid volume lost", 100.0 * *flow.volume_lost);
  line += fmt::format("; simpleFoam {} in {} iterations (residuals U {:.1e}, p {:.1e}), dp/L {:.4g} Pa/m = ",
                      flow.converged ? "converged" : "NOT converged", flow.iterations, flow.residual_u,
                      flow.residual_p, flow.pressure_gradient_bed_pa_m);
  if (flow.exact_pa_m)
    line += fmt::format("the exact {:.4g} Pa/m {:+.3f} %", *flow.exact_pa_m, 100.0 * flow.relative_error_to_exact);
  else if (flow.bound)
    line += fmt::format("{:.4f} x the untreated array's {:.4g} Pa/m, a bound from {}", flow.ratio_to_bound,
                        flow.bound->pa_m, flow.bound->side());
  else
    line += fmt::format("{:.3f} x Eisfeld & Schnitzlein at the bed's eps", flow.ratio_to_eisfeld_schnitzlein_bed);
  if (flow.ratio_to_eisfeld_schnitzlein && !flow.bound)
    line += fmt::format(" ({:.3f} x at the meshed eps)", *flow.ratio_to_eisfeld_schnitzlein);
  if (!out.info.walls) return;
  line += fmt::format("; the walls carry {:.1f} % of the drag", 100.0 * flow.drag.wall_share());
  if (!flow.exact_pa_m && !flow.bound)
    line += fmt::format(" ({:.1f} % of the wetted area)", 100.0 * flow.wall_share_of_drag_eisfeld_schnitzlein);
}

}  // namespace

CaseStage case_stage(std::shared_ptr<const meshing::PolyMesh> mesh, std::shared_ptr<const meshing::TriangleMesh> surface,
                     const Bed& bed,
                     const cases::CaseParams& p, const Provenance& prov, const std::string& scene_toml,
                     const std::filesystem::path& fluid_stl, const std::filesystem::path& case_dir, bool overwrite,
                     const cases::TreatedSolid& treated, const Console& console, const CasePieces* pieces) {
  const StageMeter meter;
  const std::string note = fmt::format("bedforge {}, seed {}", prov.version, prov.seed ? std::to_string(*prov.seed) : "none");
  // The domain's extent and patches: from gmsh's cells, from the surface snappyHexMesh meshes, or
  // for a case in pieces its inlet and outlet heights.
  std::vector<std::string> patches;
  if (mesh)
    for (const auto& patch : mesh->patches) patches.push_back(patch.name);
  else if (surface)
    patches = surface->patches;
  const std::vector<Eigen::Vector3d> ends =
      pieces ? std::vector<Eigen::Vector3d>{{0.0, 0.0, pieces->inlet_z}, {0.0, 0.0, pieces->outlet_z}}
             : std::vector<Eigen::Vector3d>{};
  const cases::CaseGeometry g = cases::case_geometry(mesh ? mesh->points : surface ? surface->points : ends, bed);
  CaseStage out;
  // An earlier run's pieces wait aside while the case is written anew: the ranks keep those made
  // from the same inputs.
  const std::filesystem::path aside = pieces ? cases::set_pieces_aside(case_dir) : std::filesystem::path();
  out.info = cases::write_case(case_dir, overwrite, mesh.get(), patches, g, bed, p, note, scene_toml, bed_to_csv(bed, prov),
                               fluid_stl, treated);
  if (pieces) {
    cases::put_pieces_back(aside, case_dir, pieces->count);
    pieces->write(out.info);
  }
  if (surface) out.info.surface_volume_m3 = meshing::enclosed_volume(*surface);  // what snappyHexMesh's cells should fill
  out.report = out.info.to_json();
  std::string line = pieces ? fmt::format("case: {} {} in {} pieces (one rank each) in {}", out.info.cells,
                                          p.polyhedra ? "polyhedra" : "cells", pieces->count, case_dir.string())
                     : !mesh ? fmt::format("case: snappyHexMesh's set-up in {} (not a validated route: check its "
                                           "cells, docs/mesh_case_benchmark.md)",
                                           case_dir.string())
                     : p.polyhedra
                         ? fmt::format("case: {} polyhedra (the dual of {} cells) in {}", out.info.cells, mesh->cells,
                                       case_dir.string())
                         : fmt::format("case: {} cells in {}", mesh->cells, case_dir.string());
  mesh.reset();
  surface.reset();
  release_free_memory();
  line += fmt::format(", Re_p {}, u {:.3g} m/s", p.reynolds, out.info.velocity_m_s);
  if (bed.size() > 0) {
    line += fmt::format(", bed section eps {:.4f}", out.info.section.void_fraction_bed);
    if (out.info.section.void_fraction) line += fmt::format(" (meshed {:.4f})", *out.info.section.void_fraction);
  }
  // Polyhedra that Allrun's checkMesh will fail are said here, before the run (not refused: see
  // meshing::check_polyhedra).
  if (out.info.polyhedra_quality && out.info.polyhedra_quality->failing_cells > 0)
    line += "; checkMesh will fail " + out.info.polyhedra_quality->failure;
  if (p.run) run_flow(out, line, console);
  finish_stage(out.report, meter, line, console);
  return out;
}

void solve_case_stage(CaseStage& written, const Console& console) {
  const StageMeter meter;
  std::string line = fmt::format("case: {} solved", written.info.directory.string());
  run_flow(written, line, console);
  finish_stage(written.report, meter, line, console);
}

}  // namespace bedforge::pipeline
