#include "pipeline/mesh_stage.hpp"

#include <fmt/format.h>

namespace bedforge::pipeline {

MeshStage mesh_stage(const meshing::TriangleMesh& surface, double exact_volume_m3, const Bed& bed,
                     const meshing::VolumeMeshParams& p, const std::filesystem::path& msh_path,
                     const std::filesystem::path& bad_cells_path, const Console& console) {
  const StageMeter meter;
  std::filesystem::create_directories(bad_cells_path.parent_path());
  Progress progress("mesh", console.progress);
  auto vm = std::make_shared<meshing::VolumeMesh>(
      meshing::build_volume_mesh(surface, bed, reference_diameter(bed), p, msh_path, bad_cells_path, progress));
  progress.finish();
  MeshStage out{vm, std::move(vm->report)};
  nlohmann::json& j = out.report;
  const meshing::CellQuality& q = vm->quality;
  const double volume_error = (q.total_volume - exact_volume_m3) / exact_volume_m3;
  j["parameters"] = meshing::to_json(p);
  j["fluid_volume_exact_m3"] = exact_volume_m3;
  j["fluid_volume_relative_error"] = volume_error;
  std::string line = fmt::format(
      "mesh ({}): {} cells, max non-orthogonality {:.1f} deg (mean {:.1f}, {} faces > 70), max skewness {:.2f}, "
      "max aspect ratio {:.1f}, volume error {:.2e}",
      j["algorithm"].get<std::string>(), vm->mesh.cells, q.max_non_orthogonality_deg, q.mean_non_orthogonality_deg,
      q.faces_over_70_deg, q.max_skewness, q.max_aspect_ratio, volume_error);
  if (j.contains("layers")) {
    const auto& l = j["layers"];
    line += fmt::format("; {} prism layers, mean thickness {:.3g} d, {} of {} stacks at full thickness",
                        p.layers.count, l["mean_thickness_d"].get<double>(), l["stacks_at_full_thickness"].get<long>(),
                        l["stacks"].get<long>());
  }
  finish_stage(j, meter, line, console);
  return out;
}

}  // namespace bedforge::pipeline
