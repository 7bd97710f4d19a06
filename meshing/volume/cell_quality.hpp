#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

#include "core/bed.hpp"
#include "meshing/surface/defect_locations.hpp"
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// Limits a volume mesh must meet, in the terms of OpenFOAM's checkMesh; every face pyramid must
// also be positive (checkMesh's face pyramid check). checkMesh itself fails a mesh at
// non-orthogonality >= 90 deg, skewness > 4, aspect ratio > 1000 or a volume <= 0; the default
// non-orthogonality limit is tighter because simpleFoam's non-orthogonal correction loses
// accuracy and robustness long before 90 deg.
struct QualityGate {
  double max_non_orthogonality_deg = 85.0;
  double max_skewness = 4.0;
  double max_aspect_ratio = 1000.0;
  double min_volume_d3 = 1e-12;  // smallest cell volume, in reference diameters cubed
  double min_face_pyramid_m3 = 0.0;  // smallest face pyramid, m^3 (absolute, as checkMesh's)
};

// checkMesh's own limits, which a case's polyhedra (the dual of tetrahedra that passed
// QualityGate) are checked against: a case that fails them fails Allrun's checkMesh. The dual is
// not held to the tetrahedra's 85 deg: it exceeds that on meshes that pass checkMesh and whose
// flow converges (docs/findings.md, session 44). The volume limit is the tetrahedra's. A face
// pyramid fails checkMesh below -SMALL = -1e-15 m^3 (primitiveMesh::checkFacePyramids' default),
// whatever the mesh's size: a cell of a 3 mm bed at -1e-8 d^3 (-2.7e-16 m^3) passes it.
inline constexpr QualityGate kCheckMeshLimits{90.0, 4.0, 1000.0, 1e-12, -1e-15};

// Per-cell and summary quality of a PolyMesh, with OpenFOAM's definitions
// (primitiveMeshTools): non-orthogonality of an internal face is the angle between its area
// vector and the owner-to-neighbour centre vector; skewness is the distance from the face
// centre to where that centre vector crosses the face, over the face's extent in that
// direction (boundary faces: from the owner centre along the normal); aspect ratio is the
// larger of the ratio of the cell's projected areas and (sum |S_f|)/6/V^(2/3); a face pyramid
// is the volume between a face and a cell's centre, S_f . (x_f - x_c) / 3, signed so that it is
// positive when the face's area vector points away from the cell.
struct CellQuality {
  std::vector<double> non_orthogonality_deg;  // per cell: worst over its internal faces
  std::vector<double> skewness;               // per cell: worst over its faces
  std::vector<double> aspect_ratio;           // per cell
  std::vector<double> volume;                 // per cell, m^3
  std::vector<double> min_face_pyramid;       // per cell, m^3: its smallest face pyramid (negative: inverted)

  double max_non_orthogonality_deg = 0.0, mean_non_orthogonality_deg = 0.0;  // internal faces; mean as checkMesh: acos(mean cos)
  long faces_over_70_deg = 0;                  // checkMesh's "severely non-orthogonal"
  double max_skewness = 0.0, max_aspect_ratio = 0.0;
  double min_volume = 0.0, total_volume = 0.0;  // m^3
  long inverted_face_pyramids = 0;              // face pyramids < 0, counted from each side of a face
  std::vector<long> non_orthogonality_histogram;  // internal faces in 10-degree bins, 0-10 ... 80-90+

  // Cells failing `gate` (d_ref in m scales the volume limit).
  std::vector<int> bad_cells(const QualityGate& gate, double d_ref) const;
  nlohmann::json to_json(double d_ref) const;
};

CellQuality cell_quality(const PolyMesh& mesh);
CellQuality cell_quality(const PolyhedralMesh& mesh);

// One face's figures, as CellQuality's definitions: its area vector (m^2), its non-orthogonality
// (internal faces; 0 on the boundary), its skewness, and its pyramids from the owner's centre and
// from the neighbour's (m^3; 0 for a boundary face's neighbour).
//   points, face      the mesh's points (m) and the face's point labels
//   owner_centre      the owner cell's centre (m); neighbour_centre: the neighbour's, null on the boundary
struct FaceFigures {
  Eigen::Vector3d area = Eigen::Vector3d::Zero();
  double non_orthogonality_deg = 0.0, skewness = 0.0, pyramid_owner = 0.0, pyramid_neighbour = 0.0;
  bool fails(const QualityGate& gate) const;  // a limit of `gate` that concerns faces, or an inverted pyramid
};
FaceFigures face_figures(const std::vector<Eigen::Vector3d>& points, std::span<const int> face,
                         const Eigen::Vector3d& owner_centre, const Eigen::Vector3d* neighbour_centre);

// Where the cells `bad` of `m` (quality `q`) lie: the particle nearest to each and the summary
// of locate_defects; when `path` is not empty, the cells are also written there as legacy VTK,
// the polygons of their faces each carrying its cell's quality and nearest particle, for ParaView.
DefectLocations locate_bad_cells(const Bed& bed, const PolyMesh& m, const CellQuality& q, const std::vector<int>& bad,
                                 const std::filesystem::path& path);
DefectLocations locate_bad_cells(const Bed& bed, const PolyhedralMesh& m, const CellQuality& q,
                                 const std::vector<int>& bad, const std::filesystem::path& path);

}  // namespace bedforge::meshing
