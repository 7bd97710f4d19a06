#pragma once
#include <cstddef>
#include <vector>

#include "meshing/surface/surface_checks.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// What split_wall_triangles_off_delaunay did.
struct WallDelaunaySplits {
  std::size_t missing_before = 0;  // wall triangles not in the Delaunay tetrahedra of the points, at first
  std::size_t missing_after = 0;   // the same when the rounds stopped
  std::size_t edges_split = 0;     // in the rounds
  int rounds = 0;
  bool kept = true;                // the splits are in the surface: none was left missing, or none was made
};

// gmsh's tetrahedra start from the Delaunay tetrahedra of the surface's points. A surface
// triangle that is not one of their facets must be recovered, and gmsh's recovery (TetGen's)
// holds the whole mesh a second time: about three times the memory and the time of a mesh
// that needs none (docs/findings.md, 2026-11-26). Wall triangles miss where the vertices of a
// sphere near the wall come inside every sphere through their corners. This splits the longest
// wall edge of each triangle with no empty sphere through its corners at its midpoint, laid on
// the cylinder, round by round until none is left or `max_rounds` have run. A split that would
// make a triangle with an angle under 10 degrees is not made (along a hole's loop, whose edges
// cannot be split, triangles would thin round by round): such a triangle is left to gmsh. When
// some are left after the rounds, every split is undone: gmsh's recovery of a few costs it as
// much as of all (docs/findings.md, 2026-11-26, late), and the splits cost angle. The shape is
// unchanged but for the split edges' sagitta (the new vertices lie on the wall, as the
// mesher's own do).
//
// Each wall triangle is first tested on the points within `band` of it, on the safe side: the
// spheres through its corners have their centres on one line, each point rules out a half-line
// of them, and one that passes keeps an interval whatever lies farther. The few that fail are
// then looked up in CGAL's Delaunay tetrahedra of the points near them, and only those missing
// there (certainly missing from gmsh's too) are split: a split vertex can itself spoil a
// neighbouring flat face, so none is made needlessly.
//
// Inputs: `f`, a welded surface (m); `pieces`, f's triangle ranges as build_fluid_surface makes
// them (those of Shape::cylinder are the walls); `band` (m), larger than the wall triangles'
// circumradii; `rings` (m): heights of the walls' rings (wall_mesh), whose edges are not split
// (their points are what two windows of one bed must agree on). Output: f with new points at
// its end and each wall's triangles still one range; `pieces`' ranges moved to match; or both as
// they were (`kept` false).
WallDelaunaySplits split_wall_triangles_off_delaunay(TriangleMesh& f, std::vector<SurfacePiece>& pieces, double band,
                                                     const std::vector<double>& rings = {}, int max_rounds = 2);

}  // namespace bedforge::meshing
