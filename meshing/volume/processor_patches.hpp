#pragma once
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

}  // namespace bedforge::meshing
