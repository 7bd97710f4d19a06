#pragma once
#include <cstddef>
#include <vector>

#include "meshing/surface_checks.hpp"
#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// What split_wall_triangles_off_delaunay did.
struct WallDelaunaySplits {
  std::size_t missing_before = 0;  // wall triangles not in the Delaunay tetrahedra of the points, at first
  std::size_t missing_after = 0;   // the same when it stopped (0 unless `max_rounds` ran out)
  std::size_t edges_split = 0;
  int rounds = 0;
};

// gmsh's tetrahedra start from the Delaunay tetrahedra of the surface's points. A surface
// triangle that is not one of their facets must be recovered, and gmsh's recovery (TetGen's)
// holds the whole mesh a second time: about three times the memory and the time of a mesh
// that needs none (docs/findings.md, 2026-11-26). Wall triangles miss where the vertices of a
// sphere near the wall come inside every sphere through their corners. This splits the longest
// wall edge of each missing triangle at its midpoint, laid on the cylinder, round by round
// until none is missing or `max_rounds` have run. The shape is unchanged but for the split
// edges' sagitta (the new vertices lie on the wall, as the mesher's own do).
//
// Inputs: `f`, a welded surface (m); `pieces`, f's triangle ranges as build_fluid_surface makes
// them (those of Shape::cylinder are the walls); `band` (m): only the points within it of a
// wall are triangulated, to keep the triangulation small (a triangle passed could still be
// missing through a sphere deeper than the band, holding no point of it and one beyond).
// Output: f with new points at its end and each wall's triangles still one range; `pieces`'
// ranges moved to match.
WallDelaunaySplits split_wall_triangles_off_delaunay(TriangleMesh& f, std::vector<SurfacePiece>& pieces, double band,
                                                     int max_rounds = 8);

}  // namespace bedforge::meshing
