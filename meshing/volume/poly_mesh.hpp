#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <initializer_list>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bedforge::meshing {

// A face of a tetrahedron, pyramid or prism: 3 or 4 point indices, in order around it.
struct Face {
  std::array<int, 4> v{-1, -1, -1, -1};
  int n = 0;
  Face() = default;
  Face(std::initializer_list<int> points);
  explicit Face(const std::array<int, 3>& t) : v{t[0], t[1], t[2], -1}, n(3) {}
  int size() const { return n; }
  int operator[](int k) const { return v[k]; }
  int& operator[](int k) { return v[k]; }
  const int* begin() const { return v.data(); }
  const int* end() const { return v.data() + n; }
  int* begin() { return v.data(); }
  int* end() { return v.data() + n; }
};

// A cell by its points in gmsh's node order: tetrahedron (4), pyramid (5: the base quad, then
// the apex) or prism (6: a triangle, then the opposite one, point k + 3 across from point k).
struct VolumeCell {
  std::array<int, 6> v{-1, -1, -1, -1, -1, -1};
  int n = 0;
};

// A volume mesh in OpenFOAM's face-addressed form (constant/polyMesh): every face once,
// internal faces first in upper-triangular order (by owner, then neighbour), then the boundary
// faces patch by patch. A face's normal (right-hand rule) points out of its owner, so boundary
// normals point out of the domain.
struct PolyMesh {
  struct Patch {
    std::string name;
    std::string type;  // OpenFOAM patch type: "patch" (inlet, outlet), "wall", "cyclic" or "processor"
    int start = 0, size = 0;
    // cyclic only (cyclic_patches.hpp): the other patch, and the translation from this one to it (m)
    std::string neighbour;
    Eigen::Vector3d separation = Eigen::Vector3d::Zero();
    // processor only (processor_patches.hpp): this piece's processor and the one across the patch
    int processor = -1, neighbour_processor = -1;
  };
  std::vector<Eigen::Vector3d> points;  // m
  std::vector<Face> faces;
  std::vector<int> owner;               // per face
  std::vector<int> neighbour;           // per internal face
  std::vector<Patch> patches;
  int cells = 0;
  int internal_faces() const { return static_cast<int>(neighbour.size()); }
};

// Polygons of any size in one compact list (OpenFOAM's faceCompactList): face f's points are
// points[offsets[f]] ... points[offsets[f + 1] - 1].
struct Polygons {
  std::vector<int> offsets{0};
  std::vector<int> points;
  std::size_t size() const { return offsets.size() - 1; }
  std::span<const int> operator[](std::size_t f) const {
    return {points.data() + offsets[f], static_cast<std::size_t>(offsets[f + 1] - offsets[f])};
  }
  void push_back(std::span<const int> face) {
    points.insert(points.end(), face.begin(), face.end());
    offsets.push_back(static_cast<int>(points.size()));
  }
};

// A PolyMesh whose faces are polygons of any size: the polyhedral dual (dual_mesh.hpp).
struct PolyhedralMesh {
  std::vector<Eigen::Vector3d> points;  // m
  Polygons faces;
  std::vector<int> owner;
  std::vector<int> neighbour;
  std::vector<PolyMesh::Patch> patches;
  int cells = 0;
  int internal_faces() const { return static_cast<int>(neighbour.size()); }
};

// The index of `mesh`'s patch called `name` (PolyMesh or PolyhedralMesh); std::runtime_error
// naming the patch and the patches there are when it has none.
template <class Mesh>
int patch_number(const Mesh& mesh, const std::string& name) {
  std::string there;
  for (std::size_t k = 0; k < mesh.patches.size(); ++k) {
    if (mesh.patches[k].name == name) return static_cast<int>(k);
    there += (k ? ", " : "") + mesh.patches[k].name;
  }
  throw std::runtime_error("the mesh has no patch `" + name + "` (its patches: " + there + ")");
}

// Face f's point labels, whichever way the mesh stores its faces.
inline std::vector<int> points_of(const PolyMesh& m, int f) { return {m.faces[f].begin(), m.faces[f].end()}; }
inline std::vector<int> points_of(const PolyhedralMesh& m, int f) {
  const auto face = m.faces[f];
  return {face.begin(), face.end()};
}

// Cells with labelled boundary faces into a PolyMesh.
//   points      P x 3, m
//   cells       C cells, either orientation (each face is turned to point away from its cell's
//               vertex mean, right for the convex and nearly convex cells meshers make)
//   boundary    B faces, the domain's boundary
//   patch       B, index into `names` for each boundary face
//   names/types patch names and OpenFOAM types, in the order the patches are written
//   point_map   when given, set to each input point's index in the mesh (P; -1 if no cell uses it)
// Cells are numbered bottom to top (by centroid z), which keeps the matrix bandwidth small in a
// column; points in the order the faces first use them. std::runtime_error when a cell face is on the boundary but in no patch, or a face is
// shared by more than two cells, with its location.
// OpenFOAM's type of a patch bedforge names: "patch" for inlet and outlet, else "wall".
std::string patch_type(const std::string& name);

PolyMesh poly_mesh_from_cells(std::vector<Eigen::Vector3d> points, const std::vector<VolumeCell>& cells,
                              const std::vector<Face>& boundary, const std::vector<int>& patch,
                              const std::vector<std::string>& names, const std::vector<std::string>& types,
                              std::vector<int>* point_map = nullptr);

// The cells of a mesh of tetrahedra as their points (the inverse of poly_mesh_from_cells), in
// cell order; each tetrahedron's points in the order its faces first name them.
//   mesh   tetrahedra only (gmsh's cells without prism layers)
// Returns C cells of 4 points.
std::vector<VolumeCell> tetrahedra(const PolyMesh& mesh);

// Face centre and area vector (|S| = area, along the normal) as OpenFOAM computes them
// (primitiveMeshFaceCentresAndAreas): exact for a triangle; a polygon is split into triangles
// about its vertex mean and their area-weighted centres averaged.
struct FaceGeometry {
  Eigen::Vector3d centre, area;
};
FaceGeometry face_geometry(const std::vector<Eigen::Vector3d>& points, std::span<const int> face);
inline FaceGeometry face_geometry(const std::vector<Eigen::Vector3d>& points, const Face& face) {
  return face_geometry(points, std::span<const int>(face.begin(), face.end()));
}

// Cell centres and volumes (m, m^3; volumes signed) as OpenFOAM computes them
// (primitiveMeshCellCentresAndVols): pyramids from each face to the mean of the face centres.
struct CellGeometry {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> volumes;
};
CellGeometry cell_geometry(const PolyMesh& mesh);
CellGeometry cell_geometry(const PolyhedralMesh& mesh);
std::vector<Eigen::Vector3d> cell_centres(const PolyMesh& mesh);
std::vector<double> cell_volumes(const PolyMesh& mesh);

// Whether any cell is a prism (two triangular and three quadrilateral faces): gmsh's cells have
// them only in prism layers; a hexahedron (six quadrilaterals) is not one.
bool has_prisms(const PolyMesh& mesh);

}  // namespace bedforge::meshing
