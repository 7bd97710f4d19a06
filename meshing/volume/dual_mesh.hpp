#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "meshing/volume/cell_quality.hpp"
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// The polyhedral dual of a volume mesh, made as OpenFOAM's `polyDualMesh <angle>` makes it
// (meshDualiser with its simple feature marking), so that a case can be written on the dual
// without running polyDualMesh, whose peak was about 1 kB per tetrahedron.
//   mesh                  tetrahedra (pyramids, prisms too), m; points all used
//   cell_centres          C x 3, m: its cells' centres as OpenFOAM computes them
//                         (cell_geometry(mesh).centres, which the caller has already)
//   feature_angle_deg     a boundary edge between faces whose normals differ by more than this,
//                         or between two patches, is a feature edge: its ends stay points of the
//                         dual, and its midpoint too
// Returns one cell per point of `mesh`, numbered as the points sorted by z (bottom to top, a small
// matrix bandwidth in a column). Its points: the cells' centres (OpenFOAM's), the boundary faces'
// centres, the feature points and the midpoints of the boundary edges at a feature point. Each
// edge of `mesh` becomes an internal face through the centres of the cells around it (and of the
// two boundary faces, and its midpoint, when it lies on the boundary); each boundary point
// becomes, per patch, a face through the centres of its boundary faces, or, at a feature point,
// one quadrilateral per boundary face (the point, two edge midpoints, the face's centre), joined
// into one face where consecutive boundary faces lie in one plane (polyDualMesh keeps them
// apart; on a cyclic pair of planes such small faces were skewed past checkMesh's limit).
// Internal faces come in upper-triangular order, boundary faces patch by patch as in `mesh`.
//   cell_points           when given, set to the point of `mesh` of each dual cell (C' = P)
// std::runtime_error, with the location, when an edge's cells do not form a ring (a mesh
// that is not a manifold there).
//   join_flat             false: every feature point's quadrilaterals apart, as polyDualMesh
//                         makes them (to compare with it)
PolyhedralMesh dual_mesh(const PolyMesh& mesh, const std::vector<Eigen::Vector3d>& cell_centres,
                         double feature_angle_deg, std::vector<int>* cell_points = nullptr, bool join_flat = true);

// Checks a case's polyhedra against checkMesh's limits (kCheckMeshLimits), so that cells Allrun's
// checkMesh will fail are found, located and said by bedforge before the run. Two judged cells
// across an internal face that fails (skewed past 4, or seen from the wrong side: where a sphere
// touches the container wall, docs/findings.md) are first merged into one, as agglomerating
// meshers mend such cells (the face goes, the cell keeps the other faces of both, so it stays
// closed; OpenFOAM allows two faces between two cells), and the mesh is judged again. Cells that
// still fail are reported, not refused: the coarser levels of the default scene's study fail on
// faces at the particles (docs/findings.md, 2026-11-29), and a dual that passes there is not made yet.
//   dual            the polyhedra, m; merged in place
//   judged          per cell of `dual`, whether it is judged and may be merged (empty: every
//                   cell): a piece's own cells, judged with its neighbours' cells around them, as
//                   `checkMesh -parallel` judges them across the processor patches
//   cell_points     when given, per cell of `dual` its point (dual_mesh's); kept in step with the
//                   merges (a merged cell keeps its first cell's point)
//   bed, d_ref      name the particles near failing cells; d_ref (m) scales the volume limit
//   what            the mesh, as `failure` names it (e.g. "piece 2 of 4's polyhedra")
//   bad_cells_path  where failing cells go, as legacy VTK (an earlier file there is removed when
//                   every cell passes)
// Returns the judged cells' worst figures, the merges made, and the cells still failing with a
// sentence saying which limits, near which particles, and where they were written ("" if none).
struct JudgedQuality {
  long cells = 0, merged_cells = 0, failing_cells = 0;
  double max_non_orthogonality_deg = 0.0, max_skewness = 0.0, max_aspect_ratio = 0.0;
  double min_volume = 0.0, min_face_pyramid = 0.0;  // m^3
  std::string failure;
  long ears_cut = 0;  // flat ears cut off the tetrahedra before the dual was made (flat_ears.hpp)
  nlohmann::json to_json(double d_ref) const;
  static JudgedQuality from_json(const nlohmann::json& j, double d_ref);  // to_json's inverse
  // Adds another part of the same mesh (a piece's): counts summed, worst figures kept, failures
  // joined, as check_polyhedra would judge both parts as one mesh.
  void add(const JudgedQuality& part);
};
JudgedQuality check_polyhedra(PolyhedralMesh& dual, std::vector<bool> judged, std::vector<int>* cell_points,
                              const Bed& bed, double d_ref, const std::string& what,
                              const std::filesystem::path& bad_cells_path);

}  // namespace bedforge::meshing
