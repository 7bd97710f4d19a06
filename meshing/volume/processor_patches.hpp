#pragma once
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// One piece of a mesh cut into axial pieces (slabs numbered from 0 upwards), made into the
// processor<piece> part of a decomposed OpenFOAM case: its bottom plane (its `inlet` patch, when
// piece > 0) becomes the processor patch procBoundary<piece>to<piece-1>, its top plane (`outlet`,
// when piece < pieces - 1) procBoundary<piece>to<piece+1>; the inlet and outlet stay as patches
// without faces, so that every piece lists the same patches in the same order, the processor
// patches last, as OpenFOAM wants them.
//   mesh    PolyMesh (gmsh's cells) or PolyhedralMesh (their dual) of the piece, m; its inlet
//           and outlet flat
// Two pieces sharing a plane order its faces alike without seeing each other: by their points'
// x and y (bit for bit the same on both sides: the surface stage triangulates a shared plane
// alike, and the dual takes a boundary triangle's centre from its points in coordinate order),
// each face starting at its point of least x (then y) and running as its own normal wants. So
// face k of one side is face k of the other, its points in reverse order from the same 0th: the
// form decomposePar gives the neighbour's copy. std::runtime_error when the mesh has no inlet or
// outlet patch, or when piece is not in [0, pieces).
// On gmsh's cells the pieces' cells are their slabs', each held to the gate. On their dual the cell of a
// point on a plane is cut in two halves, one per piece, whose centres lie close to the plane:
// a face between two halves can fail checkMesh (skewness 4.2-4.3, or an inverted face pyramid
// near a sphere at the wall, on a = 4, N = 60 beds, 2026-11-29). Whole cells across the plane
// need each piece to see its neighbour's cells next to it: not done yet (issue 58).
template <class Mesh>
void make_processor_patches(Mesh& mesh, int piece, int pieces);

}  // namespace bedforge::meshing
