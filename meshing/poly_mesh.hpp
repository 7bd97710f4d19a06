#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <string>
#include <vector>

namespace bedforge::meshing {

// A tetrahedral volume mesh in OpenFOAM's face-addressed form (constant/polyMesh): every face
// once, internal faces first in upper-triangular order (by owner, then neighbour), then the
// boundary faces patch by patch. A face's normal (right-hand rule) points out of its owner,
// so boundary normals point out of the domain.
struct PolyMesh {
  struct Patch {
    std::string name;
    std::string type;  // OpenFOAM patch type: "patch" (inlet, outlet) or "wall"
    int start = 0, size = 0;
  };
  std::vector<Eigen::Vector3d> points;  // m
  std::vector<std::array<int, 3>> faces;
  std::vector<int> owner;               // per face
  std::vector<int> neighbour;           // per internal face
  std::vector<Patch> patches;
  int cells = 0;
  int internal_faces() const { return static_cast<int>(neighbour.size()); }
};

// Tetrahedra with labelled boundary triangles into a PolyMesh.
//   points      P x 3, m
//   tets        T x 4 point indices, either orientation
//   boundary    B x 3 point indices, the domain's boundary triangles
//   patch       B, index into `names` for each boundary triangle
//   names/types patch names and OpenFOAM types, in the order the patches are written
// Cells are numbered bottom to top (by centroid z), which keeps the matrix bandwidth small in a
// column. std::runtime_error when a tet face is on the boundary but in no patch, or a face is
// shared by more than two tets, with its location.
PolyMesh poly_mesh_from_tets(std::vector<Eigen::Vector3d> points, std::vector<std::array<int, 4>> tets,
                             const std::vector<std::array<int, 3>>& boundary, const std::vector<int>& patch,
                             const std::vector<std::string>& names, const std::vector<std::string>& types);

// The four point indices of each tetrahedral cell, C x 4, in no particular order.
std::vector<std::array<int, 4>> cell_tets(const PolyMesh& mesh);
// Cell centres and volumes of the tetrahedral cells (m, m^3); volumes are signed.
std::vector<Eigen::Vector3d> cell_centres(const PolyMesh& mesh);
std::vector<double> cell_volumes(const PolyMesh& mesh);

}  // namespace bedforge::meshing
