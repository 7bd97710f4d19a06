#pragma once
#include <cstddef>
#include <vector>

#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// gmsh's tetrahedra start from the Delaunay tetrahedra of the surface's points and recover every
// surface triangle that is not one of their facets, at several times their memory
// (docs/findings.md, 2026-11-26). Of `triangles` (indices into m.triangles), those that are no
// facet of CGAL's Delaunay tetrahedra of the points `points` (indices into m.points, each once,
// holding every corner of those triangles). More points only take facets away, so each one
// returned is missing from gmsh's start too, whatever else the surface holds.
std::vector<std::size_t> off_delaunay_facets(const TriangleMesh& m, const std::vector<int>& points,
                                             const std::vector<std::size_t>& triangles);

}  // namespace bedforge::meshing
