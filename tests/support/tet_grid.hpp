#pragma once
// A grid of unit cubes split into tetrahedra: a volume mesh with known faces, patches and
// volumes, for the units that take one.
#include <array>
#include <string>
#include <vector>

#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::meshing {

// An n x n x n grid of unit cubes, each split into six tetrahedra along its main diagonal
// (Kuhn), boundary triangles labelled by the cube face they lie on: x0 x1 y0 y1 z0 z1.
struct Grid {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 4>> tets;
  std::vector<std::array<int, 3>> boundary;
  std::vector<int> patch;
};

inline Grid kuhn_grid(int n) {
  Grid g;
  auto id = [n](int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) g.points.emplace_back(i, j, k);
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& p : perms) {
          std::array<int, 3> c{i, j, k};
          std::array<int, 4> t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          g.tets.push_back(t);
        }
  // Boundary: every tet face whose three points share a coordinate at 0 or n.
  for (const auto& t : g.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      for (int a = 0, b = 0; a < 4; ++a)
        if (a != skip) f[b++] = t[a];
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          const double v = side * n;
          if (g.points[f[0]][axis] == v && g.points[f[1]][axis] == v && g.points[f[2]][axis] == v) {
            g.boundary.push_back(f);
            g.patch.push_back(2 * axis + side);
          }
        }
    }
  return g;
}

// The grid's patches, by the index kuhn_grid gives each side, and their OpenFOAM types.
inline const std::vector<std::string> kNames{"x0", "x1", "y0", "y1", "z0", "z1"};
inline const std::vector<std::string> kTypes{"patch", "patch", "wall", "wall", "wall", "wall"};

// The tetrahedra and boundary triangles in poly_mesh_from_cells's terms.
inline PolyMesh poly_mesh_from_tets(const std::vector<Eigen::Vector3d>& points, const std::vector<std::array<int, 4>>& tets,
                             const std::vector<std::array<int, 3>>& boundary, const std::vector<int>& patch,
                             const std::vector<std::string>& names, const std::vector<std::string>& types) {
  std::vector<VolumeCell> cells;
  for (const auto& t : tets) cells.push_back({{t[0], t[1], t[2], t[3], -1, -1}, 4});
  std::vector<Face> faces;
  for (const auto& t : boundary) faces.emplace_back(t);
  return poly_mesh_from_cells(points, cells, faces, patch, names, types);
}

}  // namespace bedforge::meshing
