#pragma once
#include <string>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// Makes two boundary patches of a mesh periodic along z, as OpenFOAM's cyclic patches want
// them: face k of `upper` is face k of `lower` a period up, its points in reverse order from the
// twin of its first point (the 0th points match), both patches typed "cyclic" with each other
// as neighbour and the translation between them.
//   mesh    PolyMesh (gmsh's cells) or PolyhedralMesh (their dual), m; the patches' faces flat
//           at one height each, `upper` above `lower`
// Only `upper`'s faces are reordered and turned; twins are found by their points' x and y,
// which must agree bit for bit (the surface stage meshes the upper plane as a copy of the
// lower, and gmsh and the dual keep them). std::runtime_error naming the first point or face
// without a twin, and how many there are. Returns the period (m, upper z - lower z).
template <class Mesh>
double match_cyclic_patches(Mesh& mesh, const std::string& lower, const std::string& upper);

}  // namespace bedforge::meshing
