#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "meshing/triangle_mesh.hpp"

namespace bedforge::meshing {

// A part of a surface meshed on its own: triangles [first, last) of the mesh. A sphere piece's
// triangles are facets of the convex hull of points on the sphere (centre, radius in m), as
// sphere_mesh makes them; such a piece is checked by the argument below, the others pair by pair.
struct SurfacePiece {
  std::size_t first = 0, last = 0;
  bool on_sphere = false;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

// How check_surface looks for self-intersections.
enum class SelfIntersectionTest {
  skip,       // not at all (the volume and the topology alone)
  all_pairs,  // CGAL's test on every pair of triangles whose boxes meet
  // CGAL's test on the triangles that the argument below leaves: every triangle of a piece not on
  // a sphere, and those of a sphere piece whose box meets a triangle of another piece that can
  // reach it. Nothing else can intersect: a convex polytope's facets meet only in shared edges
  // and vertices, so no two triangles of one sphere piece do; and every triangle of a sphere
  // piece lies in its ball, so two sphere pieces whose balls are disjoint cannot meet. A sphere
  // piece with a vertex off its sphere (by more than 1e-9 of the radius and the rounding to 12
  // digits) is tested like the others.
  by_pieces,
};

// What CGAL says about a surface (Polygon Mesh Processing): whether it is a 2-manifold polygon
// mesh, closed, free of self-intersections, and the volume it encloses (signed: positive when
// the normals point out of the enclosed region).
struct SurfaceCheck {
  bool manifold = false;
  bool closed = false;
  SelfIntersectionTest self_intersection_test = SelfIntersectionTest::skip;  // the one that ran
  std::size_t triangles_tested_pairwise = 0;  // of the self-intersection test: the others were covered by the argument
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

// `pieces` (used by by_pieces only): ranges covering every triangle of `mesh` once, in order.
// A surface that is not closed and manifold gets no self-intersection test (test stays skip).
SurfaceCheck check_surface(const TriangleMesh& mesh, SelfIntersectionTest test,
                           const std::vector<SurfacePiece>& pieces = {});

// Pairs of triangles of `mesh` (closed and manifold) that meet other than in a shared edge or
// vertex, as indices into mesh.triangles; CGAL's box-intersection test, on every core.
std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_triangles(const TriangleMesh& mesh);

// "(x, y, z) m used by k triangles;" for the first `count` defective edges, for error messages.
std::string describe_defects(const SurfaceCheck& check, std::size_t count = 5);

}  // namespace bedforge::meshing
