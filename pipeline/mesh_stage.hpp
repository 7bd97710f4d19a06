#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "core/bed.hpp"
#include "meshing/volume_mesh.hpp"
#include "pipeline/console.hpp"

namespace bedforge::pipeline {

// The volume mesh of the fluid domain and its report entry.
struct MeshStage {
  std::shared_ptr<const meshing::VolumeMesh> volume;  // m; passed the quality gate
  nlohmann::json report;                              // stages.mesh, with "summary"
};

// Meshes the closed labelled `surface` (m) with gmsh (meshing::build_volume_mesh), its volume
// compared with `exact_volume_m3`, the volume of the geometry the surface approximates. Writes
// the gmsh mesh to `msh_path` when not empty, the cells failing the gate to `bad_cells_path`
// when it fails.
MeshStage mesh_stage(const meshing::TriangleMesh& surface, double exact_volume_m3, const Bed& bed,
                     const meshing::VolumeMeshParams& params, const std::filesystem::path& msh_path,
                     const std::filesystem::path& bad_cells_path, const Console& console);

}  // namespace bedforge::pipeline
