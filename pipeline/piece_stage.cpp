#include "pipeline/piece_stage.hpp"

#include <fmt/format.h>

#include <numeric>
#include <vector>

#include "cases/case_writer.hpp"
#include "core/error.hpp"
#include "core/stage_meter.hpp"
#include "meshing/volume/dual_mesh.hpp"
#include "meshing/volume/processor_patches.hpp"
#include "meshing/volume/slab_mesh.hpp"

namespace bedforge::pipeline {

nlohmann::json piece_stage(const Bed& bed, const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, int piece, int pieces,
                           const std::filesystem::path& case_dir, const std::string& note, const Console& console) {
  const StageMeter meter;
  if (!std::filesystem::is_directory(case_dir / "0"))
    throw InputError(fmt::format("{}: no case to write a piece into (no 0/ fields); write the case first, e.g. "
                                 "`bedforge run` with case.run = false",
                                 case_dir.string()));
  if (!meshing::slabs_possible(surface, mesh))
    throw InputError(fmt::format("contacts.treatment = \"{}\", contacts.wall_treatment = \"{}\", mesh.layers.count = "
                                 "{}: a piece's planes would cut treated contacts or prism layers open; allowed for "
                                 "pieces: contacts.treatment and contacts.wall_treatment \"shrink\" or \"none\", "
                                 "mesh.layers.count = 0",
                                 meshing::treatment_name(surface.treatment),
                                 meshing::treatment_name(surface.wall_treatment), mesh.layers.count));
  const double d = reference_diameter(bed);
  Progress progress("piece", console.progress);
  progress.update(fmt::format("piece {} of {}: surface and cells", piece + 1, pieces));
  meshing::VolumeMesh slab =
      meshing::mesh_slab(bed, surface, piece, pieces, d, mesh, case_dir / fmt::format("bad_cells_piece{}.vtk", piece), true);
  // The bed section of the whole domain (its ends as asked), and the piece's fluid in it.
  const meshing::SurfaceParams whole = meshing::slab_surface(bed, surface, 0, 1);
  const cases::CaseGeometry g =
      cases::case_geometry({Eigen::Vector3d(0, 0, whole.clip_bottom_d * d), Eigen::Vector3d(0, 0, whole.clip_top_d * d)}, bed);
  const cases::BedSection section = cases::bed_section(nullptr, g, g.periodic ? 0.0 : case_params.section_exclude_d);
  const meshing::CellGeometry cells = meshing::cell_geometry(slab.mesh);
  double fluid = 0.0, in_section = 0.0;
  for (std::size_t c = 0; c < cells.volumes.size(); ++c) {
    fluid += cells.volumes[c];
    if (cells.centres[c].z() > section.z_low && cells.centres[c].z() < section.z_high) in_section += cells.volumes[c];
  }
  nlohmann::json report = {{"piece", piece},
                           {"pieces", pieces},
                           {"slab", slab.report},
                           {"fluid_volume_m3", fluid},
                           {"section_fluid_volume_m3", in_section},
                           {"section_z_m", {section.z_low, section.z_high}}};
  progress.update(fmt::format("piece {} of {}: {} cells written", piece + 1, pieces, slab.mesh.cells));
  if (case_params.polyhedra) {
    meshing::PolyhedralMesh dual = meshing::dual_mesh(slab.mesh, cells.centres, cases::kDualFeatureAngleDeg);
    slab = meshing::VolumeMesh();
    release_free_memory();  // the tetrahedra
    meshing::make_processor_patches(dual, piece, pieces);
    report["cells"] = dual.cells;
    meter.record(report);
    cases::write_case_piece(case_dir, piece, dual, case_params.binary, note, report);
  } else {
    meshing::make_processor_patches(slab.mesh, piece, pieces);
    report["cells"] = slab.mesh.cells;
    meter.record(report);
    cases::write_case_piece(case_dir, piece, slab.mesh, case_params.binary, note, report);
  }
  progress.finish();
  return report;
}

}  // namespace bedforge::pipeline
