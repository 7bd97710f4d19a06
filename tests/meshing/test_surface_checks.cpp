// The surface checks find what makes a surface open, badly oriented or non-manifold, and where.
#include "meshing/surface_checks.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "meshing/primitives.hpp"

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
  const SurfaceCheck k = check_surface(tetrahedron(), SelfIntersectionTest::all_pairs);
  EXPECT_TRUE(k.closed && k.manifold && k.self_intersection_test != SelfIntersectionTest::skip && !k.self_intersecting);
  EXPECT_TRUE(k.defects.empty());
  EXPECT_NEAR(k.volume, 1.0 / 6.0, 1e-15);
}

TEST(SurfaceCheck, AMissingFaceLeavesItsThreeEdgesUsedOnce) {
  TriangleMesh m = tetrahedron();
  m.triangles.pop_back();  // face (1, 2, 3)
  m.patch.pop_back();
  const SurfaceCheck k = check_surface(m, SelfIntersectionTest::all_pairs);
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
  const SurfaceCheck k = check_surface(flipped, SelfIntersectionTest::all_pairs);
  EXPECT_FALSE(k.closed);
  ASSERT_EQ(k.defects.size(), 3u);  // its edges are used twice in the same direction
  for (const auto& d : k.defects) EXPECT_EQ(d.triangles, 2);
  TriangleMesh fin = tetrahedron();
  fin.points.push_back({0.5, 0.5, -1.0});
  fin.triangles.push_back({0, 1, 4});
  fin.patch.push_back(0);
  const SurfaceCheck f = check_surface(fin, SelfIntersectionTest::all_pairs);
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
  const SurfaceCheck k = check_surface(m, SelfIntersectionTest::all_pairs);
  EXPECT_TRUE(k.closed);
  EXPECT_FALSE(k.manifold) << "the origin is a pinched vertex";
}

namespace {

// Unit spheres (edge 0.2) at `centres`, each a sphere piece, and then `extra` as a piece of its own.
struct Pieces {
  TriangleMesh mesh;
  std::vector<SurfacePiece> pieces;
};
Pieces spheres(const std::vector<Eigen::Vector3d>& centres, const TriangleMesh& extra = {}) {
  Pieces out;
  for (const auto& c : centres) {
    const std::size_t first = out.mesh.triangles.size();
    out.mesh.append(sphere_mesh(c, 0.5, {}, 0.2, 1.5, true, "particles"));
    out.pieces.push_back({first, out.mesh.triangles.size(), true, c, 0.5});
  }
  if (!extra.triangles.empty()) {
    const std::size_t first = out.mesh.triangles.size();
    out.mesh.append(extra);
    out.pieces.push_back({first, out.mesh.triangles.size()});
  }
  return out;
}

}  // namespace

// The test by pieces against CGAL's test of all pairs, on surfaces built to intersect where the
// argument (surface_checks.hpp) must not be used and not where it may.
TEST(SurfaceCheck, ByPiecesLeavesApartSpheresToTheArgumentAndFindsOverlappingOnes) {
  const Pieces apart = spheres({{0, 0, 0}, {1.01, 0, 0}});
  const SurfaceCheck a = check_surface(apart.mesh, SelfIntersectionTest::by_pieces, apart.pieces);
  EXPECT_FALSE(a.self_intersecting);
  EXPECT_EQ(a.triangles_tested_pairwise, 0u) << "disjoint balls, each a convex polytope's facets";
  const Pieces overlapping = spheres({{0, 0, 0}, {0.8, 0, 0}});
  EXPECT_TRUE(check_surface(overlapping.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  const SurfaceCheck o = check_surface(overlapping.mesh, SelfIntersectionTest::by_pieces, overlapping.pieces);
  EXPECT_TRUE(o.self_intersecting);
  EXPECT_GT(o.triangles_tested_pairwise, 0u);
  EXPECT_LT(o.triangles_tested_pairwise, overlapping.mesh.triangles.size()) << "only the faces near the other ball";
}

TEST(SurfaceCheck, ByPiecesFindsAnotherPiecePokingIntoASphere) {
  TriangleMesh tip = tetrahedron();
  for (auto& p : tip.points) p = Eigen::Vector3d(0.4, 0.0, 0.0) + 0.5 * p;  // a vertex 0.4 from the centre: inside
  const Pieces s = spheres({{0, 0, 0}}, tip);
  EXPECT_TRUE(check_surface(s.mesh, SelfIntersectionTest::by_pieces, s.pieces).self_intersecting);
  for (auto& p : tip.points) p.x() += 0.5;  // now clear of the sphere
  const Pieces clear = spheres({{0, 0, 0}}, tip);
  EXPECT_FALSE(check_surface(clear.mesh, SelfIntersectionTest::by_pieces, clear.pieces).self_intersecting);
}

TEST(SurfaceCheck, ByPiecesTestsASpherePieceWithAVertexOffItsSphereWhole) {
  // One vertex pushed through the centre and out of the far side: the piece folds through itself, and
  // the argument no longer holds for it (its vertex is off the sphere).
  Pieces s = spheres({{0, 0, 0}});
  s.mesh.points[0] = -1.5 * s.mesh.points[0];
  EXPECT_TRUE(check_surface(s.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  const SurfaceCheck k = check_surface(s.mesh, SelfIntersectionTest::by_pieces, s.pieces);
  EXPECT_TRUE(k.self_intersecting);
  EXPECT_EQ(k.triangles_tested_pairwise, s.mesh.triangles.size());
}

TEST(SurfaceCheck, ByPiecesRefusesPiecesThatDoNotCoverTheMeshOnce) {
  Pieces s = spheres({{0, 0, 0}, {2, 0, 0}});
  s.pieces.pop_back();
  EXPECT_THROW(check_surface(s.mesh, SelfIntersectionTest::by_pieces, s.pieces), std::invalid_argument);
}
