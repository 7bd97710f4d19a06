#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// What CGAL says about a surface (Polygon Mesh Processing): whether it is a 2-manifold polygon
// mesh, closed, free of self-intersections, and the volume it encloses (signed: positive when
// the normals point out of the enclosed region).
struct SurfaceCheck {
  bool manifold = false;
  bool closed = false;
  bool self_intersections_checked = false;  // skipped above the triangle limit (the test is O(n log n) but slow)
  bool self_intersecting = false;
  double volume = 0.0;                      // m^3
  // Edges not shared by exactly two triangles of opposite orientation: midpoint (m) and the
  // number of triangles using it. What makes a surface open or non-manifold, and where.
  struct Defect {
    Eigen::Vector3d at;
    int triangles;
  };
  std::vector<Defect> defects;
  nlohmann::json to_json() const;
};

SurfaceCheck check_surface(const TriangleMesh& mesh, long self_intersection_limit);

// Pairs of triangles of `mesh` (closed and manifold) that meet other than in a shared edge or
// vertex, as indices into mesh.triangles; CGAL's box-intersection test, on every core.
std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_triangles(const TriangleMesh& mesh);

// "(x, y, z) m used by k triangles;" for the first `count` defective edges, for error messages.
std::string describe_defects(const SurfaceCheck& check, std::size_t count = 5);

}  // namespace bedforge::meshing
