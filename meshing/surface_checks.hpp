#pragma once
#include <nlohmann/json.hpp>

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
  nlohmann::json to_json() const;
};

SurfaceCheck check_surface(const TriangleMesh& mesh, long self_intersection_limit);

}  // namespace bedforge::meshing
