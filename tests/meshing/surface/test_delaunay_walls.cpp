// Wall triangles split until each is a facet of the Delaunay tetrahedra of the surface's
// points, which gmsh's tetrahedra start from: counted here by CGAL's triangulation of all of
// them, independently of the function's own test of each triangle's circumspheres.
#include "meshing/surface/delaunay_walls.hpp"

#include <gtest/gtest.h>

#include "meshing/surface/primitives.hpp"
#include "meshing/surface/wall_mesh.hpp"
#include "support/delaunay_facets.hpp"

using namespace bedforge::meshing;

namespace {

// A tube of radius R = d (d = 3 mm) closed at both ends, its wall meshed at 0.5 d, and one
// sphere (0.1 d edges) `gap` from its wall: the pieces as build_fluid_surface makes them, the
// wall first.
struct Scene {
  TriangleMesh f;
  std::vector<SurfacePiece> pieces;
};
Scene tube_with_sphere(double gap) {
  const double d = 0.003, R = d, H = 2 * d, edge = 0.5 * d;
  Scene s;
  s.f = wall_mesh(R, 0.0, H, edge, {}, 1.3, true, "wall").outside;
  SurfacePiece wall;
  wall.last = s.f.triangles.size(), wall.shape = SurfacePiece::Shape::cylinder, wall.radius = R;
  s.pieces.push_back(wall);
  s.f.append(ring_mesh(Frame::along({0, 0, 0}, Eigen::Vector3d::UnitZ()), 0.0, R, edge, kBreakCocircular, false, "inlet"));
  s.f.append(ring_mesh(Frame::along({0, 0, H}, Eigen::Vector3d::UnitZ()), 0.0, R, edge, kBreakCocircular, true, "outlet"));
  s.f.append(sphere_mesh({R - 0.5 * d - gap, 0.0, 0.5 * H}, 0.5 * d, {}, 0.1 * d, 1.3, false, "particles"));
  s.f.weld();
  SurfacePiece rest;
  rest.first = wall.last, rest.last = s.f.triangles.size();
  s.pieces.push_back(rest);
  return s;
}

}  // namespace

TEST(DelaunayWalls, WallTrianglesFacingASphereNearTheWallBecomeDelaunayFacets) {
  const double d = 0.003, R = d;
  Scene s = tube_with_sphere(0.01 * d);
  const long before = test_support::triangles_gmsh_must_recover(s.f, s.pieces[0].first, s.pieces[0].last);
  ASSERT_GT(before, 0) << "the scene no longer has wall triangles off the Delaunay tetrahedra; it tests nothing";
  const std::size_t points = s.f.points.size(), others = s.pieces[1].last - s.pieces[1].first;

  const WallDelaunaySplits r = split_wall_triangles_off_delaunay(s.f, s.pieces, 1.0 * d);

  EXPECT_EQ(static_cast<long>(r.missing_before), before);
  EXPECT_EQ(r.missing_after, 0u);
  EXPECT_TRUE(r.kept);
  EXPECT_EQ(test_support::triangles_gmsh_must_recover(s.f, s.pieces[0].first, s.pieces[0].last), 0);
  // Every split adds one point and two triangles, all to the wall, whose range stays first.
  EXPECT_EQ(s.f.points.size(), points + r.edges_split);
  EXPECT_EQ(s.pieces[0].first, 0u);
  EXPECT_EQ(s.pieces[1].first, s.pieces[0].last);
  EXPECT_EQ(s.pieces[1].last - s.pieces[1].first, others);
  EXPECT_EQ(s.pieces[1].last, s.f.triangles.size());
  for (std::size_t t = s.pieces[0].first; t < s.pieces[0].last; ++t) EXPECT_EQ(s.f.patches[s.f.patch[t]], "wall");
  // The new points lie on the wall, and the surface is still closed, manifold and unbroken.
  for (std::size_t v = points; v < s.f.points.size(); ++v)
    EXPECT_NEAR(std::hypot(s.f.points[v].x(), s.f.points[v].y()), R, 1e-12 * R);
  const SurfaceCheck check = check_surface(s.f, SelfIntersectionTest::all_pairs);
  EXPECT_TRUE(check.closed);
  EXPECT_TRUE(check.manifold);
  EXPECT_FALSE(check.self_intersecting);
}

TEST(DelaunayWalls, LeavesAWallThatIsAlreadyDelaunayAsItIs) {
  Scene s = tube_with_sphere(0.3 * 0.003);
  ASSERT_EQ(test_support::triangles_gmsh_must_recover(s.f, s.pieces[0].first, s.pieces[0].last), 0);
  const TriangleMesh before = s.f;
  const WallDelaunaySplits r = split_wall_triangles_off_delaunay(s.f, s.pieces, 0.003);
  EXPECT_EQ(r.missing_before, 0u);
  EXPECT_EQ(r.edges_split, 0u);
  EXPECT_EQ(s.f.triangles, before.triangles);
  EXPECT_EQ(s.f.points, before.points);
}

// A sphere 0.002 d off the wall: each split brings new wall triangles inside its vertices'
// reach (2 missing, then 6 after two rounds, as measured when this test was written).
TEST(DelaunayWalls, UndoesSplitsThatCannotFinish) {
  Scene s = tube_with_sphere(0.002 * 0.003);
  const long before = test_support::triangles_gmsh_must_recover(s.f, s.pieces[0].first, s.pieces[0].last);
  const TriangleMesh surface = s.f;
  const std::vector<SurfacePiece> pieces = s.pieces;

  const WallDelaunaySplits r = split_wall_triangles_off_delaunay(s.f, s.pieces, 0.003);

  ASSERT_GT(r.edges_split, 0u) << "no split was tried; the test tests nothing";
  ASSERT_GT(r.missing_after, 0u) << "the splits finished here; the test tests nothing";
  EXPECT_FALSE(r.kept);
  EXPECT_EQ(s.f.points, surface.points);
  EXPECT_EQ(s.f.triangles, surface.triangles);
  EXPECT_EQ(s.f.patch, surface.patch);
  ASSERT_EQ(s.pieces.size(), pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    EXPECT_EQ(s.pieces[k].first, pieces[k].first);
    EXPECT_EQ(s.pieces[k].last, pieces[k].last);
  }
  EXPECT_EQ(static_cast<long>(r.missing_before), before);
}
