#pragma once
#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

#include "meshing/surface/primitives.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// A hole in a container wall where the bed meets it (a bridge's end, a sphere crossing the
// wall): a closed loop of vertices on the wall, shared exactly with the part that meets it.
struct WallHole {
  std::vector<Eigen::Vector3d> loop;  // m
  double spacing = 0.0;               // distance between loop vertices (m)
  int particle = -1;                  // for error messages
};

struct WallMesh {
  TriangleMesh outside;  // the wall less its holes
  TriangleMesh inside;   // what the holes cut out (closes the bed solid there)
};

// A hole loop's vertex within this fraction of the loop's spacing of a ring moves onto it
// (snap_holes_to_rings): nearer, the wall's triangles between it and the ring would be needles.
inline constexpr double kRingSnap = 0.25;

// Moves the vertices of `holes`' loops so that each ring height in `rings` (m) meets a loop only
// at its vertices, as wall_mesh's rings need: a vertex within kRingSnap of the loop's spacing of
// a ring onto it (in z only), then the nearer end of each loop edge still crossing it along that
// edge (by at most half the edge). A loop that lies on one side of a ring and comes that near it
// has its near vertices moved away to that distance instead: snapped, the ring (and a plane cut
// there) would touch the loop at one vertex. Returns each move as (from, to): the parts that share the
// loops (a bridge's end, a sphere's cut) must move the same points alike.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> snap_holes_to_rings(std::vector<WallHole>& holes,
                                                                             const std::vector<double>& rings);

// A curved wall's end row at the height of `frame` (origin on the axis, w along it): n equal
// intervals of the circle of radius R (m), interval j in parts[j] equal parts (parts empty: one
// each, the points of circle_loop(frame, R, n) bit for bit). The points (m), their angles (rad)
// and their spacing (m), as wall_mesh and the faces sharing the row (plane_mesh's boundary) take
// them.
struct EndRow {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> angles, spacing;
};
EndRow end_row(const Frame& frame, double R, int n, const std::vector<int>& parts);

// Parts for each of the n intervals of the end rows of a curved wall of radius R (m) at heights
// z0 and z1 (m), so that the rows' spacing follows `field` (at each interval's middle, the larger
// count of the two heights, so that both rows are alike): next to a sphere cut by a periodic
// plane near the wall the rows are as fine as the wall beside them. The ends' rows of
// 0.15 d between such a sphere and the wall 0.1 d from it left tetrahedra of 10 deg under the
// plane and dual cells failing checkMesh (docs/findings.md, 2026-12-01).
std::vector<int> end_row_parts(double R, int n, double z0, double z1, const SpacingField& field);

// Lateral wall of the cylinder of radius R about the z axis, z0 <= z <= z1, with holes.
// Meshed unrolled (s = R theta, z): a staggered lattice of spacing about `edge` (its end rows
// are end_row(Frame at z0 or z1, R, ring_points(R, edge), `row_parts`), the edges of the
// inlet's and outlet's faces), the
// hole loops, rings graded away from them by `growth`, thinned like sphere_mesh, and a CGAL
// constrained Delaunay triangulation with the loops as constraints (no vertex is added). The
// unrolled strip is cut along a lattice generator clear of every hole; its two sides share
// their vertices. `outward` = normals away from the axis. CutConflict when a hole crosses the
// strip's ends or no generator is clear of the holes. With a `field`, spacing as in sphere_mesh.
// `rings` (m, inside (z0, z1) by half an edge): heights where the wall has a row of vertices
// like its end rows, joined by edges to each other and to the holes' vertices on the ring (the
// holes must meet a ring only at vertices: snap_holes_to_rings), which no triangle crosses: the
// wall's section at a ring is then those points whatever else the strip holds, so two windows
// of one bed that share a ring cut the wall there alike (pieces on ranks of their own).
WallMesh wall_mesh(double R, double z0, double z1, double edge, const std::vector<WallHole>& holes, double growth,
                   bool outward, const std::string& patch, const SpacingField& field = {},
                   const std::vector<double>& rings = {}, const std::vector<int>& row_parts = {});

// Flat face in the plane z = 0 of frame `f`: inside the first of `boundary`'s loops, outside the
// others (an annulus's inner circle), less the holes. Boundary loops are vertices on the plane
// shared with the faces next to this one, and constraints; hole loops are shared with the parts
// that meet the face. Vertices as in wall_mesh: the loops, the field's seeds (those in the face),
// rings graded away from the holes, a staggered lattice of spacing about `edge`, none closer than
// 0.8 x the mean spacing to another or to a boundary edge; then a constrained Delaunay
// triangulation (no vertex is added). Normals +w if `along_w`. CutConflict when a hole vertex lies
// outside the face. A hole may come as close to the boundary as its own loop's chords allow (a
// sphere 0.005 d off the wall): the triangles in that gap are as narrow as the gap.
WallMesh plane_mesh(const Frame& f, const std::vector<std::vector<Eigen::Vector3d>>& boundary, double edge,
                    const std::vector<WallHole>& holes, double growth, bool along_w, const std::string& patch,
                    const SpacingField& field = {});

}  // namespace bedforge::meshing
