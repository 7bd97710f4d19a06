#pragma once
#include <array>
#include <filesystem>
#include <utility>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// gmsh is a process-wide singleton: one session per mesh, closed however the work ends.
struct GmshSession {
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// The volume cells bedforge exchanges with gmsh: {gmsh element type, corner count}.
constexpr std::array<std::pair<int, int>, 3> kCellTypes{{{4, 4}, {7, 5}, {6, 6}}};  // tetrahedron, pyramid, prism

// The current gmsh model's volume cells and physical boundary triangles as a PolyMesh, patches
// in a fixed order (inlet, outlet, walls, particles).
PolyMesh extract_poly_mesh();

// A volume mesh written by the mesh stage (MSH 4.1), read back (for `bedforge case DIR`).
// InputError naming the file when it is missing or gmsh cannot read it.
PolyMesh read_msh(const std::filesystem::path& msh_path);

}  // namespace bedforge::meshing
