#pragma once
#include <vector>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// An ear is a tetrahedron with two faces on one wall: all four of its points lie on the wall, so
// no optimiser pass can move them, and where the wall turns little across the ear's wall edge
// the ear is a sliver (its dihedral angle at that edge is the wall's turn). gmsh leaves such
// slivers on a tube's wall, and the polyhedra of the dual around one fail checkMesh
// (docs/findings.md, 2026-11-29, session 46). Cut off, the ear's two other faces become the wall
// and the fluid loses the ear's volume, a sliver's.

// The largest turn of the wall across an ear's wall edge (the angle between its two wall faces'
// normals) at which the ear is cut: far above a tube wall's turn between neighbouring triangles
// (edge / radius: 3-11 deg at the edges used), below the 70.5 deg of a regular tetrahedron.
inline constexpr double kEarTurnDeg = 30.0;

// The ears of `mesh` to cut: tetrahedra with exactly two boundary faces, both on one wall patch
// (type "wall"), whose normals differ by less than `max_turn_deg`, none of whose points lies on
// a patch of another type (inlet, outlet, a plane between slabs or pieces: the wall may not move
// there). Of two ears sharing a face only the first is taken.
//   mesh          cells of any shape (only tetrahedra can be ears), m
// Returns cell indices in increasing order.
std::vector<int> flat_ears(const PolyMesh& mesh, double max_turn_deg = kEarTurnDeg);

// Cuts `ears` (flat_ears' answer) off `mesh` in place: each ear's two wall faces go, its two
// other faces join that wall patch, owned by the cells beyond them and pointing out of them; the
// other cells keep their order, the points stay as they are. Returns the volume cut off, m^3.
double cut_ears(PolyMesh& mesh, const std::vector<int>& ears);

}  // namespace bedforge::meshing
