#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "core/bed.hpp"
#include "meshing/volume/slab_mesh.hpp"
#include "meshing/volume/volume_mesh.hpp"
#include "pipeline/console.hpp"
#include "pipeline/scene.hpp"

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
// With more than one slab (meshing::slab_count), the domain is meshed in slabs instead, each
// slab's surface built again from `bed` and `surface_params`.
MeshStage mesh_stage(const meshing::TriangleMesh& surface, double exact_volume_m3, const Bed& bed,
                     const meshing::SurfaceParams& surface_params, const meshing::VolumeMeshParams& params,
                     const std::filesystem::path& msh_path,
                     const std::filesystem::path& bad_cells_path, const Console& console);

// The volume mesh a scene asks for, estimated before it is made, low on purpose: a refusal on
// it never stops a run that would have fitted.
//   fluid volume: from the scene alone, the domain less the spheres, the bed at the densest
//                 random packing (eps 0.36, Scott & Kilgour 1969) so the bed is as short as it
//                 can be; once the bed is packed, the treated bed's exact fluid volume;
//   cells:        that volume over 0.24 h^3 per cell, h the surface edge (the largest volume
//                 per cell of the empty tube's meshes, 0.20-0.24 h^3 from 0.2 d to 0.07 d; beds
//                 have more, being refined at contacts: a = 10, N = 4000 at 0.1 d made 8.65 M
//                 cells where this gives 5.6 M); once the bed is packed, plus the cells its
//                 narrow gaps add with surface.cells_per_gap (meshing::fluid_domain_profile;
//                 gmsh made 1.03-1.39 times these cells in nine runs with cells_per_gap 3-8,
//                 docs/findings.md); without cells_per_gap, plus kCellsPerContactLoopEdge per
//                 edge of the loops graded from the contact edge (treated contacts, clip cuts;
//                 weighted by how much grading there is: FluidDomainSize): a calibration on
//                 a = 14, N = 1e4, bridges (8.5-9.9 cells per edge at three edges), validated on
//                 a = 5, N = 500 and a = 4, N = 40 (gmsh made 1.02-1.21 times the estimate, caps
//                 the most); and kCellsPerThinGapContact x d / edge per contact left as a thin gap
//                 (shrunk, or untreated): a calibration on a = 5, N = 500, shrink (15.2-16.2 at
//                 0.2-0.1 d, 10 taken), validated on a = 4, N = 80 (1.02-1.36; docs/findings.md,
//                 2026-12-01);
//   bytes:        460 per cell, the mesh stage's peak at a = 10, N = 4000 in one piece (3956 MB
//                 for 8.61 M cells): a calibration on that one run (a = 6, N = 860 gave 490 per
//                 cell at 2.1 M cells, where gmsh's fixed costs weigh more); 300 where the bed may
//                 be meshed in slabs (shrink or none, no prism layers, mesh.slabs not 1), from
//                 the same bed in 4 slabs (2666-2816 MB for 8.92 M cells, 313-331 bytes per cell;
//                 docs/findings.md, docs/mesh_case_benchmark.md); when the case is run, for
//                 simpleFoam's processes together, 850 on the polyhedral dual and 1200 on the
//                 tetrahedra (897 and 1038, 1300 and 1431 per tetrahedron at 5.95 M and 2.73 M
//                 tetrahedra, 2 processes; docs/findings.md).
struct MeshEstimate {
  double fluid_volume_m3 = 0.0;
  double gap_cells = 0.0;      // of `cells`, those the narrow gaps add
  double contact_cells = 0.0;  // of `cells`, those graded around contacts (without cells_per_gap)
  double cells = 0.0;
  double mesh_peak_bytes = 0.0;  // the mesh stage's
  // The mesh stage's peak as measured, not a bound: with the gaps refined, at
  // kGapsRefinedBytesPerCell per estimated cell; else mesh_peak_bytes.
  double likely_mesh_peak_bytes = 0.0;
  double peak_bytes = 0.0;       // the run's: the mesh stage's, or simpleFoam's when the case is run
  bool peak_in_solver = false;   // the peak is simpleFoam's (the case is run), not the mesh stage's
};
MeshEstimate estimate_mesh(const Scene& scene);
MeshEstimate estimate_mesh(const Scene& scene, const Bed& bed);
MeshEstimate estimate_mesh(const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, const Bed& bed);
// The same from the fluid domain's size as meshing::fluid_domain_profile gives it at
// kEstimateVolumePerCell (m^3, cells), `d` the bed's reference diameter (m), in `container`.
MeshEstimate estimate_mesh(const meshing::SurfaceParams& surface, const meshing::VolumeMeshParams& mesh,
                           const cases::CaseParams& case_params, const meshing::FluidDomainSize& fluid, double d,
                           const Container& container);
// The estimate's volume per cell in the bulk, edge^3 (above).
inline constexpr double kEstimateVolumePerCell = 0.24;
// The estimate's cells per edge of a graded loop (above).
inline constexpr double kCellsPerContactLoopEdge = 8.0;
// The estimate's cells per contact left as a thin gap, times d / edge (above).
inline constexpr double kCellsPerThinGapContact = 10.0;
// The console's line for `e` against `available_bytes`, and its report entry (stages.mesh.estimate).
std::string estimate_line(const MeshEstimate& e, double available_bytes);
nlohmann::json to_json(const MeshEstimate& e);

// InputError naming surface.edge_length_d when the estimate's peak exceeds `available_bytes`
// (core's available_memory_bytes()): said before packing, not as a crash an hour later.
void refuse_mesh_beyond_memory(const Scene& scene, double available_bytes);
// The same once `bed` is packed, before its surface: naming surface.cells_per_gap when the
// narrow gaps' cells are what does not fit. Returns the estimate.
MeshEstimate refuse_mesh_beyond_memory(const Scene& scene, const Bed& bed, double available_bytes);

// The mesh stage's peak per estimated cell with the gaps refined (cells_per_gap > 0), for a
// piece's refusal, where the bound above let a piece through that the kernel killed at 22.2 GB
// (estimated 22.2 M cells, 10.2 GB): the most measured on meshes of at least 4 M estimated
// cells, rounded up, a calibration on three runs of the scenes' ratio of contact to surface edge
// (1/3-1/4): 1126 on a = 5, N = 500 at 0.15 d in one piece, 1057 and 1052 on the middle piece of
// 12 of a = 14, N = 1e4 at 0.2 and 0.15 d (gmsh's HXT peaks at some 790 bytes per tetrahedron
// there, 1.23 times the estimated cells); validated on its piece of 24 (1077). With a contact
// edge a tenth of the surface edge runs took 490-600 per estimated cell, so a refusal there may
// stop a piece that would fit (docs/findings.md, 2026-12-01).
inline constexpr double kGapsRefinedBytesPerCell = 1150.0;

// Piece `piece` (from 0) of `pieces` (piece_stage), estimated alone as `e` (from
// meshing::slab_domain_size), with `ranks_here` ranks on this machine (OMPI_COMM_WORLD_LOCAL_SIZE,
// said in the message): InputError naming mesh.pieces and the count that would fit (the pieces
// are cut to about equal estimated cells) when e.likely_mesh_peak_bytes exceeds `available_bytes`,
// this rank's share of the machine's memory (available_memory_bytes()): a refused piece costs its
// user one more piece, a killed one its allocation. Where the narrow gaps hold most of the
// cells, the message names `s`'s cells_per_gap and contact edge too. Without refined gaps it
// errs towards trying: one rank with the whole default bed peaked at 4329 MB where its mesh
// stage took 3060 MB (docs/mesh_case_benchmark.md, pieces).
void refuse_piece_beyond_memory(const MeshEstimate& e, const meshing::SurfaceParams& s, int piece, int pieces,
                                int ranks_here, double available_bytes);

// How a piece's memory check sizes it, for a message: at kGapsRefinedBytesPerCell with the gaps
// refined, else by the bound that errs low.
std::string piece_memory_basis(bool gaps_refined);
// What a user may change when the pieces' ranks lack memory, for the "allowed:" of a message;
// `more_pieces` says how many pieces (e.g. "mesh.pieces >= 6").
std::string pieces_memory_remedies(const std::string& more_pieces);
// What makes fewer cells across the narrow gaps under `s`: its cells_per_gap and contact edge.
std::string gaps_remedy(const meshing::SurfaceParams& s);

}  // namespace bedforge::pipeline
