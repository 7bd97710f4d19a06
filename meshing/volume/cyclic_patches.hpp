#pragma once
#include <string>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// Makes two boundary patches of a mesh periodic along `axis` (0 x, 1 y, 2 z), as OpenFOAM's
// cyclic patches want them: face k of `upper` is face k of `lower` a period on, its points in
// reverse order from the twin of its first point (the 0th points match), both patches typed
// "cyclic" with each other as neighbour and the translation between them.
//   mesh    PolyMesh (gmsh's cells) or PolyhedralMesh (their dual), m; the patches' faces flat
//           at one coordinate each along `axis`, `upper` beyond `lower`
// Only `upper`'s faces are reordered and turned; twins are found by their points' other two
// coordinates, which must agree bit for bit (the surface stage meshes the upper plane as a copy
// of the lower, and gmsh and the dual keep them). std::runtime_error naming the first point or
// face without a twin, and how many there are. Returns the period (m, upper less lower).
template <class Mesh>
double match_cyclic_patches(Mesh& mesh, const std::string& lower, const std::string& upper, int axis = 2);

// The cyclic pairs a periodic bed's mesh can have, each matched where the mesh has both
// patches: x_min and x_max, y_min and y_max (a box periodic on every side), inlet and outlet
// (every periodic section). Returns how many pairs were matched.
struct CyclicPair {
  const char* lower;
  const char* upper;
  int axis;
};
inline constexpr CyclicPair kCyclicPairs[] = {{"x_min", "x_max", 0}, {"y_min", "y_max", 1}, {"inlet", "outlet", 2}};
template <class Mesh>
int match_every_cyclic_pair(Mesh& mesh);

}  // namespace bedforge::meshing
