#pragma once
#include <Eigen/Core>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "meshing/surface/spaced_points.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// Meshes of the shapes a fluid domain is made of, each on its own with vertices on the exact
// surface, so work is proportional to the number of shapes. Shapes that meet share a loop of
// vertices computed once by the same expression, so their meshes weld into one (no booleans).
// Lengths in m. `outward` = true orients normals away from the shape's inside.

// An orthonormal frame: local (x, y, z) -> origin + x u + y v + z w. `along` builds one whose
// w is `axis` (unit); for axis +z it is the identity, so z-planes keep exact coordinates.
struct Frame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::UnitX(), v = Eigen::Vector3d::UnitY(),
                  w = Eigen::Vector3d::UnitZ();
  static Frame along(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis);
  Frame turned(double angle) const;  // turned by `angle` (rad) about w
  Eigen::Vector3d to_world(const Eigen::Vector3d& local) const { return origin + local.x() * u + local.y() * v + local.z() * w; }
};

// Vertex j of n on the circle of radius R at local height z, half a step on if `stagger`.
Eigen::Vector3d on_circle(double R, int j, int n, bool stagger, double z);
// Vertices on a circle of radius R for a target edge: at least 8.
int ring_points(double R, double edge);
// How far the chords of that circle lie inside it (its sagitta), in R's unit.
double ring_sagitta(double R, double edge);
// The inverse: the longest edge whose circle of radius R has a sagitta of at most `sagitta`
// (> 0, R's unit); +inf when 8 points already do.
double ring_edge_for_sagitta(double R, double sagitta);
// The loop where a shape meets a circle of radius rho in the plane z = 0 of `f`: its n
// vertices, f.to_world(on_circle(rho, j, n, false, 0)).
std::vector<Eigen::Vector3d> circle_loop(const Frame& f, double rho, int n);

// Where a sphere's mesh stops: a closed loop of vertices on the sphere (a circle for caps,
// bridges and neighbours, the wall curve for a sphere crossing a wall). The sphere keeps the
// side where `removed` is false.
// Regular rings of points (on a flat face, or parallel to a cut on a sphere) hold four points
// on a circle again and again, where a Delaunay triangulation may take either diagonal: gmsh's
// tetrahedra then miss the surface's choice and recover the face over the whole volume mesh, at
// several times their own time and memory (docs/findings.md). Moving each such point at random
// (seeded, the same every run) by up to kBreakCocircular / 2 of its spacing in each direction
// leaves one Delaunay triangulation, which the surface and gmsh both find. Caps keep their
// rings regular (jitter 0): a cap faces another across a thin gap, and two layouts moved
// independently leave slivers between them (the second of two facing caps is turned by half a
// rim step instead: the same layout on both sets four points in a plane across the gap).
constexpr double kBreakCocircular = 2e-3;

struct SphereCut {
  std::vector<Eigen::Vector3d> loop;              // in order, on the sphere (m)
  double spacing = 0.0;                           // distance between loop vertices (m)
  double jitter = kBreakCocircular;               // of the rings graded from the loop
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit, from the centre into the removed part
  std::function<bool(const Eigen::Vector3d&)> removed;
  // The fluid ends at the cut (a wall, a clip, slab or periodic plane): `removed` holds beyond the
  // loop off the sphere too, and match_sphere_volume keeps the moved vertices clear of it. False
  // for a contact's cut (bridge, cap, union), beyond whose plane the fluid goes on around it.
  bool fluid_ends = false;
  // Whether a hull face whose three vertices all lie on this loop spans the removed part (and is
  // dropped); unset: every such face does. A loop along two planes (a sphere cut at a box's edge)
  // also holds faces on the sphere that turn its corners, which are kept.
  std::function<bool(const Eigen::Vector3d&, const Eigen::Vector3d&, const Eigen::Vector3d&)> spans;
};

// Thrown when cuts on one sphere overlap or leave a loop edge out of the mesh; the caller
// names the particles.
struct CutConflict : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Sphere (centre c, radius r) minus its cuts, open along every cut's loop. Vertices: the loops,
// the field's seeds (those on the kept side), rings graded away from each loop (spacing growing by
// `growth` per ring up to `edge`), and a spherical Fibonacci lattice of spacing `edge` elsewhere,
// thinned so no two lie closer than 0.8 x their mean spacing; the triangles are their convex hull
// (the Delaunay triangulation on the sphere) less the faces spanning a loop; a loop vertex off the
// sphere (moved onto a wall ring, snap_holes_to_rings) is taken into the hull moved radially onto
// it and kept where it is in the mesh. The mesh's first points are the loops' vertices, loop by
// loop in the cuts' order, as given (match_sphere_volume relies on it). At least 48 vertices.
// With a `field`, no vertex is spaced wider than it asks: where it asks for less than `edge`,
// candidates come from a lattice of spacing field.finest, those asking for the least first.
TriangleMesh sphere_mesh(const Eigen::Vector3d& c, double r, const std::vector<SphereCut>& cuts, double edge,
                         double growth, bool outward, const std::string& patch, const SpacingField& field = {});

// Moves the vertices of a sphere's mesh `m` (centre c, radius r, cut along `cuts`' loops; m, as
// sphere_mesh made it, its loops' vertices first) outward along their radius so that its facets
// hold the sphere's volume, not the inscribed polyhedron's: a flat triangle with edges a, b, c on
// a sphere of radius r lies on average (a^2 + b^2 + c^2) / (24 r) inside it, and each vertex moves
// by the area-weighted mean of that over its triangles, which puts back what they cut off to
// second order. The loops' vertices stay where they are (other shapes share them), and so does a
// vertex the move would take into a cut's removed part. A vertex moves at most an eighth of its
// room beyond its triangles' edge e (root mean square); room: the distance to the nearest other
// surface (`clearance`, m, at a vertex; none: no other surface) or, along its ray, to the removed
// part of a cut the fluid ends at (SphereCut::fluid_ends). Where the room is less than e the gap
// is not resolved, its cells across it already the thinnest, and moving would thin them more
// (shrunk beds at a 0.2 d edge then fail the volume mesh's quality gate): the vertex stays. Each
// vertex stays on its ray from the centre, so the mesh stays a radial graph over the same
// spherical triangles and cannot cross itself. Returns the largest move (m), for the ball that
// holds the mesh.
double match_sphere_volume(TriangleMesh& m, const Eigen::Vector3d& c, double r, const std::vector<SphereCut>& cuts,
                           const std::function<double(const Eigen::Vector3d&)>& clearance = {});

// Largest distance between a sphere (c, r) and the planes of the mesh's triangles: an upper
// bound of the chordal deviation of an inscribed mesh.
double chordal_deviation(const TriangleMesh& m, const Eigen::Vector3d& c, double r);

// Generalised tube in frame f: generators at distance rho from the w axis, from local z = 0
// to z = length(x, y) (> 0), n vertices per ring, rings staggered by half a step, about one
// per sqrt(3)/2 of the loop spacing (at least one, so short bridges get near-equilateral
// triangles). The start loop is circle_loop(f, rho, n), the end loop tube_end_loop(f, rho, n,
// length, edge). `outward` = normals away from the axis.
using GeneratorLength = std::function<double(double x, double y)>;
TriangleMesh tube_mesh(const Frame& f, double rho, int n, const GeneratorLength& length, double edge, bool outward,
                       const std::string& patch);
std::vector<Eigen::Vector3d> tube_end_loop(const Frame& f, double rho, int n, const GeneratorLength& length, double edge);

// Flat ring r_in <= r <= r_out (r_in = 0: a disk) in the plane z = 0 of f, normal +w if
// `along_w`, triangulated Delaunay within its edge loops circle_loop(f, r, ring_points(r, edge)).
// The sites between the loops move at random by up to jitter / 2 of the edge (see
// kBreakCocircular).
TriangleMesh ring_mesh(const Frame& f, double r_in, double r_out, double edge, double jitter, bool along_w,
                       const std::string& patch);

}  // namespace bedforge::meshing
