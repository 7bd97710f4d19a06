#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/bed.hpp"
#include "core/progress.hpp"
#include "core/scene_section.hpp"
#include "meshing/volume/cell_quality.hpp"
#include "meshing/surface/defect_locations.hpp"
#include "meshing/volume/poly_mesh.hpp"
#include "meshing/volume/prism_layers.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Volume mesh of the fluid domain with gmsh, scene section [mesh]. Lengths in reference
// diameters d. The surface's own triangles fix the cell size at the boundary, so refinement at
// the particles and in the gaps near contacts is set by [surface] edge_length_d and
// contact_edge_length_d; inside, gmsh interpolates between the boundary sizes, capped at
// `max_size_d` (in a packed bed every point is within about d/2 of a surface, so the cap acts
// mostly in the empty inlet and outlet sections).
struct VolumeMeshParams {
  enum class Algorithm { hxt, delaunay };
  Algorithm algorithm = Algorithm::hxt;  // the first tried; the other is the fallback
  bool fallback = true;                  // retry with the other algorithm when the gate fails
  double max_size_d = 0.25;              // largest cell edge, away from every surface
  // gmsh's tetrahedral optimiser (needed for checkMesh's aspect ratio); when its passes leave
  // cells failing the gate, HXT meshes again with its own optimisation, on one thread and
  // several times slower, which clears the slivers in the narrow wedges of enlarged contacts
  // (skipped when its memory, estimated from the cells and memory of the attempt before it,
  // exceeds what is available).
  bool optimize = true;
  int max_optimize_passes = 3;           // optimiser passes: the first always, more while cells fail the gate
  int threads = 0;                       // 0: every core
  // Axial slabs meshed one at a time and joined (meshing/volume/slab_mesh.hpp), so that gmsh's memory
  // follows a slab, not the bed: 0 chooses (slab_count), 1 meshes in one piece.
  int slabs = 0;
  // The case written in this many axial pieces, one Open MPI rank each (bedforge piece), and run
  // on as many processes without decomposePar; no process holds the whole mesh. 0 or 1: one piece.
  int pieces = 0;
  QualityGate gate;
  PrismLayerParams layers;               // [mesh.layers]; none by default
};
const char* algorithm_name(VolumeMeshParams::Algorithm a);
VolumeMeshParams read_volume_mesh_params(SceneSection& mesh);
nlohmann::json to_json(const VolumeMeshParams& p);

struct VolumeMesh {
  PolyMesh mesh;        // patches in the surface's order, `fluid` cells
  CellQuality quality;
  nlohmann::json report;
};

// Meshes the inside of `surface` (closed, labelled by patch; the fluid surface of the surface
// stage), with prism layers on the particles first when params.layers.count > 0. `bed` names
// the particles near bad cells; `d_ref` (m) scales the parameters. Writes the gmsh mesh
// (MSH 4.1, physical groups per patch and `fluid`) to `msh_path` when not empty. Tries, in
// turn: `algorithm`; HXT with its own optimisation when `algorithm` is hxt and `optimize`;
// then, with `fallback`, the other algorithm (and HXT's own optimisation after it when that is
// hxt); the report's "attempts" give each one's cells, times, quality and memory_grown_mb (what
// it grew the process by, at most). When none passes the gate, throws std::runtime_error saying how many cells fail which
// limit and near which particles, after writing them as a legacy VTK file to `bad_cells_path`
// (open it in ParaView). With `release_memory`, what each step frees goes back to the system
// before the next (a lower peak; on a = 10, N = 4000 in slabs, 1.6 times the mesh stage's time,
// since every step then faults its pages in again).
VolumeMesh build_volume_mesh(const TriangleMesh& surface, const Bed& bed, double d_ref, const VolumeMeshParams& params,
                             const std::filesystem::path& msh_path, const std::filesystem::path& bad_cells_path,
                             Progress& progress, bool release_memory = true);

}  // namespace bedforge::meshing
