#pragma once
#include <Eigen/Core>

#include <utility>
#include <vector>

#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

// Where a plane the surface is cut or ends at (a piece's, a clip window's, a periodic section's)
// passes near a sphere's end without cutting it, the fluid between them is a wedge that narrows to
// the end's gap: with the surface's edge on both sides, gmsh's tetrahedra across it come out flat
// (a = 14, N = 1e4 in 24 pieces: 5 cells at 87 deg in a gap of 0.0023 d; a = 4, N = 120: 2 cells
// at 85 deg; docs/findings.md, 2026-12-02). So both sides get vertices graded with the gap: rings
// about the end on the sphere and about the point below (or above) it on the plane, each ring's
// spacing kWedgeEdgePerGap times the gap at its distance from the end's axis, until that reaches
// the coarse edge. A plane that cuts a sphere just inside its end meets it at a small angle in a
// small loop, which the sphere's coarse facets cut into a few chords (a = 4, N = 120: 2 of 12
// pieces failed 0.0023 d inside an end, docs/findings.md, 2026-12-02): graded alike, the cut's
// depth standing for the gap where the sphere is on the plane's far side.

// 2: tetrahedra no flatter than about 2 : 1 across the wedge. Not tuned: the one value tried,
// with which every wedge of the a = 4 bed above passed (docs/findings.md, 2026-12-02).
inline constexpr double kWedgeEdgePerGap = 2.0;

// A sphere's end near a plane (m). The end is centre.z - radius above the plane when `above`
// (the sphere lies above it), else centre.z + radius below it; a gap below 0 is the depth by which
// the plane cuts the sphere inside that end.
struct EndNearPlane {
  double plane_z = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
  bool above = true;
  int sphere = -1;  // its index in the bed it was found in
  double gap() const { return above ? centre.z() - radius - plane_z : plane_z - centre.z() - radius; }
  Eigen::Vector3d end() const { return centre + Eigen::Vector3d(0.0, 0.0, above ? -radius : radius); }
};

// The ends of the spheres (`centres`, `radii`: N each, m) that lie less than coarse /
// kWedgeEdgePerGap from one of the planes z = `planes_z` (m), on either side (not on it; a sphere
// the plane cuts through its middle has no end near it), every sphere given (both
// windows of a plane hold the spheres near it, kept or not, so both find the same ends), sorted by
// plane, then x, then y, so that both windows offer them in one order.
std::vector<EndNearPlane> ends_near_planes(const std::vector<Eigen::Vector3d>& centres,
                                           const std::vector<double>& radii, const std::vector<double>& planes_z,
                                           double coarse);

// A treated sphere near a plane the surface is cut at (m). The cut's face, made from the plane's
// loops alone, would not see the spheres just above and below it, which narrow the fluid there;
// sized across the gaps they leave, its triangles match the cells gmsh grades between the
// surfaces about it (PlaneCutParams::spheres).
struct SphereNearPlane {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

// A cut's face measures gaps out to cells_per_gap x edge from a point of it, and the surfaces'
// spacing at the points it finds from their own neighbours as far again: the spheres it needs
// come within this many times cells_per_gap x edge of its plane.
inline constexpr double kSpheresNearPlaneReach = 2.0;

// The spheres (`centres`, `radii`: N each, m) whose surface comes within `reach` (m) of one of
// the planes z = `planes_z` (m), each once, every sphere given (both windows of a plane hold the
// spheres near it, so both find the same), sorted by x, then y, then z.
std::vector<SphereNearPlane> spheres_near_planes(const std::vector<Eigen::Vector3d>& centres,
                                                 const std::vector<double>& radii,
                                                 const std::vector<double>& planes_z, double reach);

// The graded rings about an end: (distance from its axis, spacing) in m, the first (0, its own
// spacing) the end itself; each next ring sqrt(3)/2 of a spacing further out, until the spacing
// kWedgeEdgePerGap x the gap there (where the plane cuts the sphere, not less than the cut's
// depth) would reach `coarse` (not included) or the ring the sphere's equator.
std::vector<std::pair<double, double>> end_rings(const EndNearPlane& e, double coarse);

// Vertices with their spacing (m), offered to a mesher before its other free sites
// (SpacingField::seeds): the rings on the sphere about its end, and on the plane about the point
// facing it, each ring turned by half a step against the sphere's (so that no ring's vertex on
// the plane lies right under one on the sphere).
Seeds sphere_end_seeds(const EndNearPlane& e, double coarse);
Seeds plane_end_seeds(const EndNearPlane& e, double coarse);

// Of `ends`, those at the plane z = `z` (m, to a billionth of `coarse`), and the seeds of a face
// in that plane about all of them.
std::vector<EndNearPlane> ends_at(const std::vector<EndNearPlane>& ends, double z, double coarse);
Seeds plane_end_seeds(const std::vector<EndNearPlane>& ends, double coarse);

}  // namespace bedforge::meshing
