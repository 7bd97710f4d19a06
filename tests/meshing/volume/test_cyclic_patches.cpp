// Cyclic patches: the upper plane's faces reordered and turned to face the lower plane's, as
// OpenFOAM's cyclic patches want them; a face without a twin is refused.
#include "meshing/volume/cyclic_patches.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace bedforge::meshing;

namespace {

// A unit cube cut into six tetrahedra about its diagonal from (0,0,0) to (1,1,1): its bottom and
// top are both split along x = y, so they are the same triangles one unit apart (and so are its
// other opposite sides). Patches inlet (z = 0), outlet (z = 1), and the four others one wall, or
// with `every_side` each its own: x_min, x_max, y_min, y_max.
PolyMesh cube(double top_x_nudge = 0.0, bool every_side = false) {
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < 8; ++k) p.emplace_back(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  p[5].x() += top_x_nudge;  // (1, 0, 1)
  // Kuhn's six tetrahedra: 0 -> 7 through the three axes in every order.
  const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  std::vector<VolumeCell> cells;
  for (const auto& path : paths) {
    VolumeCell c;
    c.v = {0, path[0], path[1], 7, -1, -1};
    c.n = 4;
    cells.push_back(c);
  }
  // Boundary triangles, each on one side of the cube, by which side: z = 0, z = 1, the four others.
  std::vector<Face> boundary;
  std::vector<int> patch;
  for (const VolumeCell& c : cells)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> t;
      for (int j = 0, m = 0; j < 4; ++j)
        if (j != skip) t[m++] = c.v[j];
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          bool on = true;
          for (int v : t) on = on && (((v >> axis) & 1) == side);
          if (!on) continue;
          boundary.push_back(Face(t));
          patch.push_back(axis == 2 ? side : every_side ? 2 + 2 * axis + side : 2);
        }
    }
  if (every_side)
    return poly_mesh_from_cells(p, cells, boundary, patch, {"inlet", "outlet", "x_min", "x_max", "y_min", "y_max"},
                                {"patch", "patch", "patch", "patch", "patch", "patch"});
  return poly_mesh_from_cells(p, cells, boundary, patch, {"inlet", "outlet", "wall"}, {"patch", "patch", "wall"});
}

}  // namespace

TEST(CyclicPatches, TheUpperFacesTurnToFaceTheLowerOnes) {
  PolyMesh m = cube();
  const double period = match_cyclic_patches(m, "inlet", "outlet");
  EXPECT_EQ(period, 1.0);
  const PolyMesh::Patch& in = m.patches[0];
  const PolyMesh::Patch& out = m.patches[1];
  ASSERT_EQ(in.size, 2);
  ASSERT_EQ(out.size, 2);
  EXPECT_EQ(in.type, "cyclic");
  EXPECT_EQ(in.neighbour, "outlet");
  EXPECT_EQ(out.neighbour, "inlet");
  EXPECT_EQ(in.separation, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(out.separation, Eigen::Vector3d(0, 0, -1));
  for (int k = 0; k < in.size; ++k) {
    const Face& a = m.faces[in.start + k];
    const Face& b = m.faces[out.start + k];
    // Point j of the upper face is point -j of the lower one, one unit up.
    for (int j = 0; j < 3; ++j)
      EXPECT_EQ(m.points[b[j]], m.points[a[(3 - j) % 3]] + Eigen::Vector3d(0, 0, 1)) << "face " << k << " point " << j;
  }
}

TEST(CyclicPatches, AFaceWithoutATwinIsRefused) {
  PolyMesh m = cube(1e-12);
  EXPECT_THROW(match_cyclic_patches(m, "inlet", "outlet"), std::runtime_error);
}

// A box periodic on every side: its three pairs matched, each along its own axis.
TEST(CyclicPatches, EveryPairOfABoxPeriodicOnEverySideIsMatchedAlongItsAxis) {
  PolyMesh m = cube(0.0, true);
  EXPECT_EQ(match_every_cyclic_pair(m), 3);
  for (const CyclicPair& pair : kCyclicPairs) {
    const PolyMesh::Patch& lower = m.patches[patch_number(m, pair.lower)];
    const PolyMesh::Patch& upper = m.patches[patch_number(m, pair.upper)];
    EXPECT_EQ(lower.type, "cyclic");
    EXPECT_EQ(lower.neighbour, pair.upper);
    EXPECT_EQ(lower.separation, Eigen::Vector3d::Unit(pair.axis));
    EXPECT_EQ(upper.separation, -Eigen::Vector3d::Unit(pair.axis));
    for (int k = 0; k < lower.size; ++k)
      for (int j = 0; j < 3; ++j)
        EXPECT_EQ(m.points[m.faces[upper.start + k][j]],
                  m.points[m.faces[lower.start + k][(3 - j) % 3]] + Eigen::Vector3d::Unit(pair.axis))
            << pair.lower << ", face " << k << " point " << j;
  }
  PolyMesh walled = cube();
  EXPECT_EQ(match_every_cyclic_pair(walled), 1);  // inlet and outlet only
}
