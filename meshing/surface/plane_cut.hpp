#pragma once
#include <memory>
#include <string>

#include "meshing/surface/end_wedges.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// A closed surface cut in two by a horizontal plane, whatever it bounds: a bed's fluid surface
// with bridges, caps or unions, which a clip window (build_fluid_surface) would open where its
// plane crosses them. The plane's face is triangulated once and given to both sides, so the
// two parts share it point for point (by construction: the same doubles), facing opposite ways.

struct PlaneCutParams {
  double edge = 0.0;  // m: the plane face's target edge away from the cut (the surface's edge)
  double growth = 1.5;  // edge growth per ring away from the cut's loops
  std::string below_patch = "outlet", above_patch = "inlet";  // the plane face's patch on each side
  // Cells across the face's narrow gaps, as [surface] cells_per_gap asks of the surfaces beside
  // it: where the section's loops face each other across the face nearer than cells_per_gap x
  // edge, the face's edge there is their distance / cells_per_gap, at least `finest` (m). 0: the
  // edge everywhere (its triangles then span a narrow gap in one step).
  double cells_per_gap = 0.0, finest = 0.0;
  // Flip and split the triangles near the plane towards Delaunay (see cut_by_plane); off, the
  // cut is left as snapped and split (to measure what they do).
  bool delaunay_flips = true;
  // Spheres' ends near the plane, passed by or cut just inside (FluidSurface::ends_near_planes, of
  // any plane: the cut takes those at its own height): the face gets plane_end_seeds about each.
  std::vector<EndNearPlane> ends{};
  // Treated spheres near the plane (FluidSurface::spheres_near_planes, of any plane: the cut takes
  // those near its own height) and their container (needed with them): with cells_per_gap, the
  // gap at a point of the face is measured to their surfaces too, above and below it, not only to
  // the loops in it, and the face takes the spacing the surfaces about it have (see cut_by_plane).
  std::vector<SphereNearPlane> spheres{};
  std::shared_ptr<const Container> container{};
};

struct PlaneCut {
  TriangleMesh below, above;  // closed, normals out of the region each bounds (m)
  long plane_triangles = 0;   // of the shared face
  long loops = 0;             // where the plane meets the surface
  long faces = 0;             // of the plane's section: the walls' and any fluid that solid rings in there
  long vertices_snapped = 0;  // surface vertices moved onto the plane along an edge (see cut_by_plane)
  long vertices_cleared = 0;  // surface vertices left near the plane and moved away from it (see cut_by_plane)
  long edges_flipped = 0;     // near the plane, towards Delaunay (see cut_by_plane)
  long edges_split = 0;       // near the plane, where the flips left triangles gmsh would recover
  long left_to_recover = 0;   // such triangles left where the splits could not take all away (both parts)
  long ends_graded = 0;       // spheres' ends near the plane that the face is graded about (PlaneCutParams::ends)
};

// `surface` (closed, welded, normals out of the region it bounds; m) cut by the plane z = `z`
// (m). The nearer end of each edge crossing the plane (within kPlaneCutSnap of the edge's length
// of it) is moved along that edge onto the plane, nearest first, so that the cut's loops are
// mostly the surface's own vertices, spaced as its edges, with no needles beside them; not
// where the plane would then pass through that vertex twice (a saddle: the necks of bridges
// and unions), touch the surface along an edge, or turn a triangle over; nor a vertex where
// patches meet. A vertex so left near the plane beside a crossing edge or a point on the plane
// moves away from it along z until its crossing edges are cut kPlaneCutClearance of the height
// difference away, at most (and with none, exactly) a tenth of its shortest edge away. Each edge still
// crossing is split where it meets the plane, and the triangles on either side are kept whole
// or split in two or three, then flipped towards Delaunay within two edges of the plane (an
// edge of one patch whose opposite angles sum to more than pi; the loops are left alone); the
// triangles there that are still no facet of the Delaunay tetrahedra of the points (checked by
// CGAL) have their longest edge off the plane split at its midpoint, round by round, so that
// gmsh, which recovers such facets at 4 times its memory, has none to recover (where the
// splits cannot finish, a part is left as the flips made it). The
// region's section by the plane is one face or more (bridged spheres and the wall can ring in a
// pocket of fluid there), each an outer loop (clockwise seen from above on the part below) less
// the holes (the solid's sections) it is the nearest to hold; each is meshed by plane_mesh with
// `p`'s edge and growth, graded about the ends of spheres near the plane (PlaneCutParams::ends),
// shorter across narrow gaps (PlaneCutParams::cells_per_gap: the gap at
// a point of the face is its distance to the nearest solid point plus that to the nearest solid
// point ahead of it, within 60 degrees of the direction away from the first, so two sides of
// one loop (spheres joined by a bridge the plane cuts) count as a gap too; the solid points are
// the loops' and the nearest points of PlaneCutParams::spheres, in 3D; and where finer, the
// spacing the surfaces have at those two points (GapSpacing), interpolated between them as gmsh
// grades its cells between surfaces), normals +z on the part below and -z above.
// CutConflict (primitives.hpp) naming the height and place when the plane meets the surface at
// a point where loops touch, or when plane_mesh cannot place a hole; std::runtime_error when
// `surface` is not closed along the plane.
// 0.5: every crossing edge, moving a vertex by up to half an edge along it. On the default bed
// in 3 slabs (2026-11-30, docs/findings.md) 0.2 left 9 and 23 plane triangles under 5 deg and
// 11 dual cells failing checkMesh, 0.4 none under 5 deg and 4 failing, 0.5 none and 2 or 3.
inline constexpr double kPlaneCutSnap = 0.5;
// 0.2: a = 14, N = 1e4 (2026-11-30, docs/findings.md) left two saddle vertices 0.0008 and
// 0.0013 d below a plane, its crossing edges cut 0.0017 d from them, and 2 of 6.2 M cells at
// 87.4 deg non-orthogonality there.
inline constexpr double kPlaneCutClearance = 0.2;
// Lawson's flips on one side's triangles with a vertex within `band` of the plane: an edge shared
// by two triangles of one patch whose angles opposite it sum to more than pi gives way to the
// other diagonal, round by round, unless that would fold the surface (a new normal more than
// 37 deg from the pair's), lay an edge in the plane, or take away a crease (the pair's normals
// more than acos(kFlipCreaseCos) apart). The snaps and splits leave such pairs by the hundred
// (a = 8, N = 1500, two planes: 631), each a triangle that is no facet of the Delaunay
// tetrahedra gmsh starts from; recovering even a few cost HXT 4 times its memory. The side's
// boundary, the loops, is left as it is.
//   x      points, m;  s: their heights above the plane, m (0: on it)
//   tris   triangles into x, flipped in place; patch: per triangle
// Returns the flips.
// 0.5 (60 deg): a bridge's rim meets its sphere at 78-90 deg, neighbours on a sphere or a bridge
// differ by under 30; flips across rims left 2 dual cells failing checkMesh's face pyramids on
// the default bed in 3 pieces (2026-11-30, docs/findings.md).
inline constexpr double kFlipCreaseCos = 0.5;
long flip_towards_delaunay(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& s,
                           std::vector<std::array<int, 3>>& tris, const std::vector<int>& patch, double band);

PlaneCut cut_by_plane(const TriangleMesh& surface, double z, const PlaneCutParams& p);

// A fluid surface made by cutting (`out.fluid`, m; d the reference diameter, m) made ready for
// the surface stage: its bed solid (the particle triangles turned to face out of the solid), one
// piece of no known shape (the self-intersection test then takes every pair near), and the
// triangles' count and quality in `out.report`.
void finish_cut_surface(FluidSurface& out, double d);

// What a report says of a cut: its counts (loops, plane triangles, vertices snapped, ...).
nlohmann::json to_json(const PlaneCut& c);

// The cut's parameters from the surface stage's `s` (d: the reference diameter, m): the
// surface's edge and its cells across gaps, down to the edge the gaps' spacing allows; with the
// surface `cut` of `bed` (the one to be cut), its spheres' ends, the spheres near its planes and
// their container.
PlaneCutParams plane_cut_params(const SurfaceParams& s, double d);
PlaneCutParams plane_cut_params(const SurfaceParams& s, const Bed& bed, const FluidSurface& cut);

}  // namespace bedforge::meshing
