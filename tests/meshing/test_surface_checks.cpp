// The surface checks find what makes a surface open, badly oriented or non-manifold, and where.
#include "meshing/surface_checks.hpp"

#include <gtest/gtest.h>

using namespace bedforge::meshing;

namespace {

// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) with outward normals.
TriangleMesh tetrahedron() {
  TriangleMesh m;
  m.points = {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  m.patch.assign(4, 0);
  m.patches = {"wall"};
  return m;
}

}  // namespace

TEST(SurfaceCheck, AClosedTetrahedronEnclosesItsVolume) {
  const SurfaceCheck k = check_surface(tetrahedron(), 100);
  EXPECT_TRUE(k.closed && k.manifold && k.self_intersections_checked && !k.self_intersecting);
  EXPECT_TRUE(k.defects.empty());
  EXPECT_NEAR(k.volume, 1.0 / 6.0, 1e-15);
}

TEST(SurfaceCheck, AMissingFaceLeavesItsThreeEdgesUsedOnce) {
  TriangleMesh m = tetrahedron();
  m.triangles.pop_back();  // face (1, 2, 3)
  m.patch.pop_back();
  const SurfaceCheck k = check_surface(m, 100);
  EXPECT_FALSE(k.closed);
  ASSERT_EQ(k.defects.size(), 3u);
  for (const auto& d : k.defects) {
    EXPECT_EQ(d.triangles, 1);
    EXPECT_NEAR(d.at.sum(), 1.0, 1e-15) << "midpoints of the edges of face (1, 2, 3) lie in x + y + z = 1";
  }
}

TEST(SurfaceCheck, AFlippedFaceAndAThirdFaceOnAnEdgeAreDefects) {
  TriangleMesh flipped = tetrahedron();
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);
  const SurfaceCheck k = check_surface(flipped, 100);
  EXPECT_FALSE(k.closed);
  ASSERT_EQ(k.defects.size(), 3u);  // its edges are used twice in the same direction
  for (const auto& d : k.defects) EXPECT_EQ(d.triangles, 2);
  TriangleMesh fin = tetrahedron();
  fin.points.push_back({0.5, 0.5, -1.0});
  fin.triangles.push_back({0, 1, 4});
  fin.patch.push_back(0);
  const SurfaceCheck f = check_surface(fin, 100);
  EXPECT_FALSE(f.closed);
  int three = 0;
  for (const auto& d : f.defects) three += d.triangles == 3;
  EXPECT_EQ(three, 1) << "edge (0, 1) carries three faces";
}

TEST(SurfaceCheck, TwoSolidsSharingOneVertexAreClosedButNotManifold) {
  TriangleMesh m = tetrahedron();
  TriangleMesh other = tetrahedron();  // reflected through the origin: it touches the first only there
  for (auto& p : other.points) p = -p;
  for (auto& t : other.triangles) std::swap(t[1], t[2]);  // a reflection turns normals inward: turn them back
  m.append(other);
  m.weld();
  const SurfaceCheck k = check_surface(m, 100);
  EXPECT_TRUE(k.closed);
  EXPECT_FALSE(k.manifold) << "the origin is a pinched vertex";
}
