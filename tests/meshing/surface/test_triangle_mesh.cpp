// Triangle quality measures against triangles whose angles are known.
#include "meshing/surface/triangle_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace bedforge::meshing;

TEST(TriangleMesh, AnglesAndEdgesOfKnownTriangles) {
  TriangleMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, std::sqrt(3.0) / 2.0, 0}};
  m.triangles = {{0, 1, 2}, {0, 1, 3}};
  m.patch = {0, 0};
  m.patches = {"particles"};
  EXPECT_NEAR(min_angle_deg(m, 0), 45.0, 1e-12);  // right isosceles
  EXPECT_NEAR(min_angle_deg(m, 1), 60.0, 1e-12);  // equilateral
  const MeshQuality q = mesh_quality(m);
  EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-12);
  EXPECT_NEAR(q.min_edge, 1.0, 1e-12);
  EXPECT_NEAR(q.max_edge, std::sqrt(2.0), 1e-12);
  // A needle, isosceles with base 1 and height 0.01: its base angles are atan(0.01 / 0.5).
  m.points.insert(m.points.end(), {{5, 0, 0}, {6, 0, 0}, {5.5, 0.01, 0}});
  m.triangles.push_back({4, 5, 6});
  m.patch.push_back(0);
  const double expected = std::atan(0.02) * 180.0 / M_PI;
  EXPECT_NEAR(min_angle_deg(m, 2), expected, 1e-9);
  EXPECT_NEAR(mesh_quality(m).min_angle_deg, expected, 1e-9);
}

TEST(TriangleMesh, TrianglesBelowAnAngleKeepTheirVerticesAndPatches) {
  // A right isosceles triangle (45 degrees) on patch 0 and a needle (atan(0.02), about 1.15
  // degrees) on patch 1: below 10 degrees only the needle, below 50 both.
  TriangleMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5.5, 0.01, 0}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  m.patch = {0, 1};
  m.patches = {"wall", "particles"};
  const TriangleMesh needles = triangles_below_angle(m, 10.0);
  ASSERT_EQ(needles.triangles.size(), 1u);
  EXPECT_EQ(needles.patches, m.patches);
  EXPECT_EQ(needles.patch, (std::vector<int>{1}));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(needles.points[needles.triangles[0][k]], m.points[m.triangles[1][k]]);
  EXPECT_EQ(triangles_below_angle(m, 50.0).triangles.size(), 2u);
  EXPECT_TRUE(triangles_below_angle(m, 1.0).triangles.empty());
}

// The enclosed volume of a box of sides 1, 2, 3 (12 triangles, normals out): its volume
// wherever it sits, and negative turned inside out.
TEST(TriangleMesh, EnclosedVolumeOfABox) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k) m.points.push_back({10.0 + (k & 1), -5.0 + 2.0 * ((k >> 1) & 1), 3.0 * (k >> 2)});
  // Two triangles per face, each face's corners in order around its outward normal.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) m.triangles.push_back({f[0], f[1], f[2]}), m.triangles.push_back({f[0], f[2], f[3]});
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {"wall"};
  EXPECT_NEAR(enclosed_volume(m), 6.0, 1e-12);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(enclosed_volume(m), -6.0, 1e-12);
}
