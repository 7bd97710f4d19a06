// Ears (tetrahedra with two faces on one wall) are cut off where the wall turns little across
// them, and only there; the mesh stays closed and loses the ear's volume, known exactly.
#include "meshing/volume/flat_ears.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>

using namespace bedforge::meshing;

namespace {

// Three tetrahedra: the ear (a, b, c, d) on a wall that folds along a-c, the wall faces a b c and
// a c d, with b and d raised by `h`; above it two tetrahedra to the apex p share the face b d p.
// The wall's two faces turn by acos((1 - 2 h^2) / (1 + 2 h^2)) across a-c (8.1 deg at h = 0.05,
// 70.5 deg at h = 0.5); the ear's volume is h / 3. The four faces to p are on `sides`.
PolyMesh folded_wall(double h, const std::string& sides) {
  std::vector<Eigen::Vector3d> x = {{0, 0, 0}, {1, 0, h}, {1, 1, 0}, {0, 1, h}, {0.5, 0.5, 1}};
  enum { a, b, c, d, p };
  std::vector<VolumeCell> cells(3);
  cells[0].v = {a, b, c, d, -1, -1}, cells[1].v = {a, b, d, p, -1, -1}, cells[2].v = {b, c, d, p, -1, -1};
  for (auto& cell : cells) cell.n = 4;
  const std::vector<Face> boundary = {{a, b, c}, {a, c, d}, {a, b, p}, {a, d, p}, {b, c, p}, {c, d, p}};
  const std::vector<int> patch = {0, 0, 1, 1, 1, 1};
  return poly_mesh_from_cells(x, cells, boundary, patch, {"wall", sides}, {"wall", patch_type(sides)});
}

std::set<int> point_set(const PolyMesh& m, int f) { return {m.faces[f].begin(), m.faces[f].end()}; }

double total_volume(const PolyMesh& m) {
  const auto v = cell_volumes(m);
  return std::accumulate(v.begin(), v.end(), 0.0);
}

}  // namespace

TEST(FlatEars, AnEarOnAWallThatTurnsLittleIsCutOffAndItsOtherFacesBecomeTheWall) {
  const double h = 0.05;
  PolyMesh m = folded_wall(h, "particles");  // the sides a wall too: their turn is 78 deg
  const double before = total_volume(m);
  const std::vector<int> ears = flat_ears(m);
  ASSERT_EQ(ears.size(), 1u);
  EXPECT_NEAR(cut_ears(m, ears), h / 3.0, 1e-15);
  EXPECT_EQ(m.cells, 2);
  EXPECT_EQ(m.internal_faces(), 1);  // b d p, between the two left
  // The wall now runs over the ear's other faces, a b d and b c d, which point out of their cells:
  // every cell's volume positive, and the two lost exactly the ear's.
  ASSERT_EQ(m.patches[0].size, 2);
  std::set<std::set<int>> wall;
  for (int f = m.patches[0].start; f < m.patches[0].start + m.patches[0].size; ++f) wall.insert(point_set(m, f));
  std::set<std::set<int>> named;  // each point by its place: a 0, b 2, c 6, d 4
  for (const auto& face : wall) {
    std::set<int> xs;
    for (int v : face) xs.insert(static_cast<int>(m.points[v].x() * 2 + m.points[v].y() * 4));
    named.insert(xs);
  }
  EXPECT_EQ(named, (std::set<std::set<int>>{{0, 2, 4}, {2, 6, 4}}));
  for (double v : cell_volumes(m)) EXPECT_GT(v, 0.0);
  EXPECT_NEAR(total_volume(m), before - h / 3.0, 1e-12);
  EXPECT_EQ(m.patches[1].size, 4);
}

TEST(FlatEars, AnEarWhereTheWallTurnsSharplyOrThatTouchesAnotherPatchStays) {
  // Turning by 70.5 deg: a well-shaped tetrahedron, not a sliver.
  EXPECT_TRUE(flat_ears(folded_wall(0.5, "particles")).empty());
  // Turning by 8.1 deg, but its points lie on the outlet too: the wall may not move there.
  EXPECT_TRUE(flat_ears(folded_wall(0.05, "outlet")).empty());
  // The limit is the turn: 8.1 deg is above a limit of 5 deg.
  EXPECT_TRUE(flat_ears(folded_wall(0.05, "particles"), 5.0).empty());
  EXPECT_EQ(flat_ears(folded_wall(0.05, "particles"), 9.0).size(), 1u);
}
