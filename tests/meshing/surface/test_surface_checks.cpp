// The surface checks find what makes a surface open, badly oriented or non-manifold, and where.
#include "meshing/surface/surface_checks.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "meshing/surface/primitives.hpp"
#include "meshing/surface/wall_mesh.hpp"

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

TEST(SurfaceCheck, AVertexNoTriangleUsesIsNoDefect) {
  TriangleMesh m = tetrahedron();
  m.points.push_back({5.0, 5.0, 5.0});  // last, so that its edge list is empty at the end of the lists
  const SurfaceCheck k = check_surface(m, SelfIntersectionTest::all_pairs);
  EXPECT_TRUE(k.closed && k.manifold && !k.self_intersecting);
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

struct Pieces {
  TriangleMesh mesh;
  std::vector<SurfacePiece> pieces;
};
using Shape = SurfacePiece::Shape;

// A piece of that shape (its triangles set by add_piece).
SurfacePiece shaped(Shape shape, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero(), double radius = 0.0) {
  SurfacePiece p;
  p.shape = shape, p.centre = centre, p.radius = radius;
  return p;
}

// Appends `part` to `s` as a piece of the given shape.
void add_piece(Pieces& s, const TriangleMesh& part, SurfacePiece shape) {
  shape.first = s.mesh.triangles.size();
  s.mesh.append(part);
  shape.last = s.mesh.triangles.size();
  s.pieces.push_back(shape);
}

// Unit spheres (edge 0.2) at `centres`, each a sphere piece, and then `extra` as a piece of its own.
Pieces spheres(const std::vector<Eigen::Vector3d>& centres, const TriangleMesh& extra = {}) {
  Pieces out;
  for (const auto& c : centres) add_piece(out, sphere_mesh(c, 0.5, {}, 0.2, 1.5, true, "particles"), shaped(Shape::sphere, c, 0.5));
  if (!extra.triangles.empty()) add_piece(out, extra, shaped(Shape::other));
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

namespace {

// Sphere (c, 0.5) cut where (x - c) . a > h and closed there by a flat disk, as the cap treatment
// makes it: the sphere a piece with its cut plane, the disk a planar piece.
void add_capped_sphere(Pieces& s, const Eigen::Vector3d& c, const Eigen::Vector3d& a, double h) {
  const double r = 0.5, rho = std::sqrt(r * r - h * h), edge = 0.05;
  const Frame f = Frame::along(c + h * a, a);
  SphereCut cut;
  cut.loop = circle_loop(f, rho, ring_points(rho, edge));
  cut.spacing = 2.0 * std::numbers::pi * rho / static_cast<double>(cut.loop.size());
  cut.axis = a;
  cut.removed = [c, a, h](const Eigen::Vector3d& q) { return (q - c).dot(a) > h; };
  SurfacePiece sphere = shaped(Shape::sphere, c, r);
  sphere.cut_planes = {{a, h}};
  add_piece(s, sphere_mesh(c, r, {cut}, 0.1, 1.5, true, "particles"), sphere);
  add_piece(s, ring_mesh(f, 0.0, rho, edge, 0.0, true, "particles"), shaped(Shape::plane));
}

// Two capped spheres whose disks face each other `gap` apart (negative: crossing).
Pieces capped_pair(double gap) {
  Pieces s;
  add_capped_sphere(s, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.3);
  add_capped_sphere(s, {0.0, 0.0, 0.6 + gap}, -Eigen::Vector3d::UnitZ(), 0.3);
  s.mesh.weld();
  return s;
}

}  // namespace

// The cap treatment's geometry: the balls overlap, the cut planes part the spheres, each disk
// lies in its plane. Only faces next to a disk's rim are left; spheres whose disks cross are found.
TEST(SurfaceCheck, ByPiecesPartsCappedSpheresByTheirCutPlanesAndFindsCrossingCaps) {
  const Pieces apart = capped_pair(0.02);
  ASSERT_TRUE(check_surface(apart.mesh, SelfIntersectionTest::all_pairs).closed);
  const SurfaceCheck a = check_surface(apart.mesh, SelfIntersectionTest::by_pieces, apart.pieces);
  EXPECT_FALSE(a.self_intersecting);
  const std::size_t disks = apart.pieces[1].last - apart.pieces[1].first + apart.pieces[3].last - apart.pieces[3].first;
  EXPECT_LT(a.triangles_tested_pairwise, disks) << "neither sphere reaches past the other's cut plane";
  const Pieces crossing = capped_pair(-0.05);
  EXPECT_TRUE(check_surface(crossing.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  EXPECT_TRUE(check_surface(crossing.mesh, SelfIntersectionTest::by_pieces, crossing.pieces).self_intersecting);
}

TEST(SurfaceCheck, ByPiecesTestsWholeAPieceOffItsShape) {
  // A disk vertex lifted 1e-6 off the disk's plane, and a cut plane that the sphere's vertices
  // cross: both pieces are then tested with every face near them, their own included.
  Pieces s = capped_pair(0.02);
  const std::size_t disk = s.pieces[1].first;
  s.mesh.points[s.mesh.triangles[disk][0]].z() += 1e-6;
  s.pieces[2].cut_planes[0].second -= 0.01;
  const SurfaceCheck k = check_surface(s.mesh, SelfIntersectionTest::by_pieces, s.pieces);
  EXPECT_FALSE(k.self_intersecting);
  EXPECT_GE(k.triangles_tested_pairwise, (s.pieces[1].last - s.pieces[1].first) + (s.pieces[2].last - s.pieces[2].first));
}

namespace {

// The tube R = 1, -1 <= z <= 1 (a cylinder piece, its ends planar pieces) and, with `sphere`,
// a sphere of radius 0.3 at `c`.
Pieces sphere_in_tube(const Eigen::Vector3d& c, bool sphere = true) {
  const double R = 1.0, edge = 0.1;
  Pieces s;
  add_piece(s, wall_mesh(R, -1.0, 1.0, edge, {}, 1.5, true, "wall").outside, shaped(Shape::cylinder, Eigen::Vector3d::Zero(), R));
  for (double z : {-1.0, 1.0})
    add_piece(s, ring_mesh(Frame::along({0, 0, z}, Eigen::Vector3d::UnitZ()), 0.0, R, edge, kBreakCocircular, z > 0.0, "end"),
              shaped(Shape::plane));
  if (sphere) add_piece(s, sphere_mesh(c, 0.3, {}, 0.1, 1.5, true, "particles"), shaped(Shape::sphere, c, 0.3));
  s.mesh.weld();
  return s;
}

}  // namespace

TEST(SurfaceCheck, ByPiecesLeavesASphereInsideTheWallAndFindsOneThroughIt) {
  const Pieces inside = sphere_in_tube({0.5, 0.0, 0.0});  // 0.2 from the wall
  const SurfaceCheck k = check_surface(inside.mesh, SelfIntersectionTest::by_pieces, inside.pieces);
  EXPECT_FALSE(k.self_intersecting);
  const Pieces empty = sphere_in_tube({}, false);
  EXPECT_EQ(k.triangles_tested_pairwise, check_surface(empty.mesh, SelfIntersectionTest::by_pieces, empty.pieces).triangles_tested_pairwise)
      << "the sphere lies inside the wall's facets and between the ends' planes: only the faces where the wall meets its ends";
  const Pieces through = sphere_in_tube({0.75, 0.0, 0.0});
  EXPECT_TRUE(check_surface(through.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  EXPECT_TRUE(check_surface(through.mesh, SelfIntersectionTest::by_pieces, through.pieces).self_intersecting);
}

TEST(SurfaceCheck, ByPiecesFindsASphereThroughAnEndPlane) {
  const Pieces through = sphere_in_tube({0.0, 0.0, 0.85});  // 0.15 past the outlet's plane
  EXPECT_TRUE(check_surface(through.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  EXPECT_TRUE(check_surface(through.mesh, SelfIntersectionTest::by_pieces, through.pieces).self_intersecting);
}

TEST(SurfaceCheck, ByPiecesFindsAPieceReachingPastACutPlaneIntoTheSphere) {
  // A tetrahedron with one vertex inside the capped sphere, below its cut plane z = 0.3, and
  // three beyond it but outside the cap's disk (radius 0.4): every face of it crosses the plane,
  // and it meets the sphere's faces only.
  Pieces s;
  add_capped_sphere(s, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.3);
  TriangleMesh tip = tetrahedron();
  tip.points = {{0.45, 0.0, 0.2}, {0.6, -0.1, 0.45}, {0.6, 0.1, 0.45}, {0.7, 0.0, 0.35}};
  add_piece(s, tip, shaped(Shape::other));
  s.mesh.weld();
  EXPECT_TRUE(check_surface(s.mesh, SelfIntersectionTest::all_pairs).self_intersecting);
  EXPECT_TRUE(check_surface(s.mesh, SelfIntersectionTest::by_pieces, s.pieces).self_intersecting);
}
