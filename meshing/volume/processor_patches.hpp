#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// One piece of a mesh of gmsh's cells cut into axial pieces (slabs numbered from 0 upwards),
// made into the processor<piece> part of a decomposed OpenFOAM case: its bottom plane (its
// `inlet` patch, when piece > 0) becomes the processor patch procBoundary<piece>to<piece-1>, its
// top plane (`outlet`, when piece < pieces - 1) procBoundary<piece>to<piece+1>; the inlet and
// outlet stay as patches without faces, so that every piece lists the same patches in the same
// order, the processor patches last, as OpenFOAM wants them. (The polyhedral dual of pieces
// needs whole cells across the planes: dual_pieces.hpp.)
//   mesh    PolyMesh of the piece (its slab's cells, each held to the gate), m; its inlet and
//           outlet flat
// Two pieces sharing a plane order its faces alike without seeing each other: by their points'
// x and y (bit for bit the same on both sides: the surface stage triangulates a shared plane
// alike), each face starting at its point of least x (then y) and running as its own normal
// wants. So face k of one side is face k of the other, its points in reverse order from the
// same 0th: the form decomposePar gives the neighbour's copy. std::runtime_error when the mesh
// has no inlet or outlet patch, or when piece is not in [0, pieces).
void make_processor_patches(PolyMesh& mesh, int piece, int pieces);

// A processor patch as it is being made: procBoundary<piece>to<neighbour>, its faces (points)
// and their cells, each face pointing out of its cell.
struct ProcessorPatch {
  PolyMesh::Patch patch;
  std::vector<std::vector<int>> faces;
  std::vector<int> owner;
};
ProcessorPatch processor_patch(int piece, int neighbour);

// A processor patch's faces in the order both sides of it agree on without seeing each other,
// given the same points bit for bit: by their points' coordinates (sorted), each face rotated to
// start at its least point (x, then y, then z), its orientation kept.
//   points  of the mesh the faces index, m
void order_processor_faces(const std::vector<Eigen::Vector3d>& points, ProcessorPatch& patch);

// A processor patch's faces as OpenFOAM compares them with its neighbour's copy when it reads a
// decomposed case (processorPolyPatch): face k's centre and area vector (primitiveMesh's), and its
// size, the largest distance of its points from its centre (coupledPolyPatch::calcFaceTol).
struct ProcessorFaces {
  int processor = -1, neighbour = -1;           // procBoundary<processor>to<neighbour>
  std::vector<Eigen::Vector3d> centres, areas;  // per face, m and m^2
  std::vector<double> sizes;                    // per face, m
};
// Those of each processor patch of `mesh` (PolyMesh or PolyhedralMesh), in patch order.
std::vector<ProcessorFaces> processor_faces(const PolyMesh& mesh);
std::vector<ProcessorFaces> processor_faces(const PolyhedralMesh& mesh);

// A piece's processor faces as a binary file beside its polyMesh, and read back; InputError naming
// the file when it is not one bedforge wrote or is cut short.
void write_processor_faces(const std::filesystem::path& path, const std::vector<ProcessorFaces>& patches);
std::vector<ProcessorFaces> read_processor_faces(const std::filesystem::path& path);

// How two sides of one plane between pieces differ where OpenFOAM would refuse them or read
// wrong neighbours: another number of faces, or faces k whose centres lie further apart than
// 1e-4 of the face's size, whose areas differ by more than 1e-4 of its size squared (OpenFOAM's
// default matchTolerance, both), or whose normals do not oppose. `what` is empty when the sides
// match; `faces` lists the faces that do not (up to the smaller side's count).
//   mine    procBoundary<p>to<n>; theirs: procBoundary<n>to<p>
struct ProcessorMismatch {
  std::string what;
  std::vector<int> faces;
};
ProcessorMismatch compare_processor_faces(const ProcessorFaces& mine, const ProcessorFaces& theirs);

// The faces `mismatch` names: their centres (m) on `mine`'s side and on the copy's, areas (m^2)
// and sizes (m), as a CSV table (ParaView: Table To Points).
void write_processor_mismatch(const std::filesystem::path& path, const ProcessorFaces& mine,
                              const ProcessorFaces& theirs, const ProcessorMismatch& mismatch);

}  // namespace bedforge::meshing
