#pragma once
#include <Eigen/Core>

#include <vector>

#include "core/container.hpp"
#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

// Edge length on the fluid surface from the width of the gap it faces, so that the volume mesh
// has about `cells_per_gap` cells across every narrow gap ([surface] cells_per_gap): the
// tetrahedra follow the surface's edge, and a gap spanned by edges as long as itself gets one.
//
// Inputs (m): the treated spheres' `centres` and `radii` (N each), `kept` (N, spheres left out
// of the surface are ignored), the container (its lateral walls), `cells_per_gap` (> 0), and
// the `finest` and `coarsest` edge.
// at(p, self), p on the surface: clamp(g / cells_per_gap, finest, coarsest), g the distance
// from p to the nearest sphere surface other than sphere `self`'s, and for a point on a sphere
// (self >= 0) to the lateral walls too; self = -1 for a point on a wall. Thread-safe.
class GapSpacing {
 public:
  GapSpacing(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
             const std::vector<char>& kept, const Container& container, double cells_per_gap, double finest,
             double coarsest);
  double at(const Eigen::Vector3d& p, int self) const;
  double finest() const { return finest_; }
  // Distance (m) from p to the nearest surface other than sphere `self`'s (the walls too when
  // self >= 0, as at()), up to cells_per_gap x coarsest.
  double gap(const Eigen::Vector3d& p, int self) const;

  // The tetrahedra a volume mesh gains from this spacing over one of the coarsest edge
  // everywhere (a count, no unit). Each kept sphere's surface between heights `z0` and `z1`
  // (m) fills the fluid along its normals out to the medial surface (where another sphere or a
  // wall is as near; no farther than half of cells_per_gap x coarsest, beyond which no surface
  // is known) with cells of volume `volume_per_cell` x edge^3 at its edge of at(), less the
  // same columns at the coarsest edge. The surface is sampled finely enough to resolve the
  // smallest refined patch (radius sqrt(cells_per_gap x finest x radius)). Low on purpose: the
  // walls' side of their gaps and the cells gmsh grades between patches are left out.
  // Given in `bins` bins of equal height from z0 to z1, each counting the surface samples in it
  // (bins x 1); proportional to 1 / volume_per_cell.
  std::vector<double> added_cells_profile(double volume_per_cell, double z0, double z1, int bins) const;

 private:
  // Distance from p to the nearest wall, up to cells_per_gap x coarsest.
  double wall_distance(const Eigen::Vector3d& p) const;
  // Distance along the unit normal `n` from p on sphere `self` to the medial surface, up to
  // half of cells_per_gap x coarsest.
  double medial_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& n, int self) const;

  const std::vector<Eigen::Vector3d>& centres_;
  const std::vector<double>& radii_;
  const std::vector<char>& kept_;
  const Container& container_;
  double cells_, finest_, coarsest_;
  PointsByCell grid_;  // kept spheres by the cell of their centre
};

}  // namespace bedforge::meshing
