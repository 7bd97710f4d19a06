#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Distance from p to the line through `centre` along the unit `axis` (m).
inline double from_axis(const Eigen::Vector3d& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d q = p - centre;
  return (q - q.dot(axis) * axis).norm();
}

// A part of a surface meshed on its own: triangles [first, last) of the mesh, and what is known
// of them by how they were made (lengths in m). The test by pieces checks each shape's premise
// on the vertices (every vertex in the sphere's ball, on the plane or the cylinder, up to 1e-9 of its size
// and the rounding of fluid.stl) and takes a piece that fails it as Shape::other.
struct SurfacePiece {
  enum class Shape {
    other,     // nothing: tested pair by pair with every face near it, its own included
    sphere,    // facets of the convex hull of points on the sphere, as sphere_mesh makes them, or
               // those points moved out along their radius (match_sphere_volume); radius: of the
               // ball that holds them all
    plane,     // a triangulation of a planar region (the plane is fitted to its vertices), as ring_mesh and plane_mesh make
    cylinder,  // a triangulation of the unrolled wall laid on the cylinder (axis through centre along axis, radius), as wall_mesh makes
  };
  std::size_t first = 0, last = 0;
  Shape shape = Shape::other;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  // Sphere: the planes that cut it (unit normal n out of the piece, offset h from the centre: the
  // piece lies where n . (x - centre) <= h).
  std::vector<std::pair<Eigen::Vector3d, double>> cut_planes;
};

// How check_surface looks for self-intersections.
enum class SelfIntersectionTest {
  skip,       // not at all (the volume and the topology alone)
  all_pairs,  // CGAL's test on every pair of triangles whose boxes meet
  // CGAL's test on the triangles that the argument below leaves: every triangle of a piece of no
  // known shape, and a triangle of the others whose box meets a triangle of another piece, neither
  // lying outside the region that holds the other's piece. Nothing else can intersect. No two
  // triangles of a piece of known shape cross: a convex polytope's facets meet only in shared
  // edges and vertices, and so do the triangles of a planar triangulation, laid on its plane or
  // on a cylinder (its edges far shorter than the radius). And a triangle cannot meet a piece when
  // it lies outside the region that holds the piece: a sphere piece's ball, less what lies
  // beyond its cut planes; a planar piece's slab,
  // as thick as its vertices stray from the plane; for a cylinder piece, the solid cylinder inside
  // its facets (at least sqrt(R^2 - (L/2)^2) from the axis with edges up to L), which a triangle
  // with its three vertices inside cannot leave, being convex.
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
