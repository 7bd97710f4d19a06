#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace bedforge::meshing {

// A triangle soup with shared vertices and a patch label per triangle (index into `patches`).
// Triangles are oriented with their normal (right-hand rule) pointing out of the region the
// mesh bounds: out of the fluid for the fluid-domain surface, out of the spheres for the bed.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> points;      // m
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> patch;                   // per triangle
  std::vector<std::string> patches;         // names, e.g. inlet, outlet, wall, inner_wall, particles

  int patch_index(const std::string& name);  // adds the name when new
  // Appends `other`, renumbering its vertices and patches.
  void append(const TriangleMesh& other);
  // Room for that many more, so appending pieces does not reallocate (and briefly double) the mesh.
  void reserve(std::size_t more_points, std::size_t more_triangles);
  // Merges vertices with bit-identical coordinates: parts meshed on their own with shared seam
  // vertices become one connected mesh.
  void weld();
};

// Volume the mesh encloses (m^3), by the divergence theorem: positive when its normals point
// out, meaningful only when it is closed.
double enclosed_volume(const TriangleMesh& mesh);

// Flips every triangle whose normal disagrees with `desired(centroid)`.
void orient_by(TriangleMesh& m, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& desired);

// Quality of a mesh: smallest interior angle (degrees), shortest and longest edge (m).
struct MeshQuality {
  double min_angle_deg = 180.0, min_edge = 0.0, max_edge = 0.0;
};
MeshQuality mesh_quality(const TriangleMesh& mesh);
// Smallest interior angle of the triangle (a, b, c), and of triangle t of `mesh` (degrees).
double min_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
double min_angle_deg(const TriangleMesh& mesh, std::size_t t);
// The triangles of `mesh` with an angle below `limit_deg`, each with its own three vertices,
// patches and labels kept (for a diagnostic file).
TriangleMesh triangles_below_angle(const TriangleMesh& mesh, double limit_deg);

}  // namespace bedforge::meshing
