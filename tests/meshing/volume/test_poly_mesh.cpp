#include "meshing/volume/poly_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "meshing/volume/cell_quality.hpp"
#include "support/tet_grid.hpp"

namespace bedforge::meshing {
namespace {

TEST(PolyMesh, FacesOfAGridOfTetsFollowOpenFoamsRules) {
  const int n = 3;
  Grid g = kuhn_grid(n);
  const PolyMesh m = poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes);
  ASSERT_EQ(m.cells, 6 * n * n * n);
  // Euler: every cell has four faces, internal ones counted twice.
  EXPECT_EQ(4 * m.cells, 2 * m.internal_faces() + (static_cast<int>(m.faces.size()) - m.internal_faces()));
  EXPECT_EQ(static_cast<int>(m.faces.size()) - m.internal_faces(), 6 * 2 * n * n);
  const std::vector<Eigen::Vector3d> cc = cell_centres(m);
  for (int f = 0; f < static_cast<int>(m.faces.size()); ++f) {
    const auto& t = m.faces[f];
    const Eigen::Vector3d area = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]);
    const Eigen::Vector3d fc = (m.points[t[0]] + m.points[t[1]] + m.points[t[2]]) / 3.0;
    EXPECT_GT(area.dot(fc - cc[m.owner[f]]), 0.0) << "face " << f << " does not point out of its owner";
    if (f < m.internal_faces()) {
      EXPECT_LT(m.owner[f], m.neighbour[f]);
      if (f > 0) {  // upper-triangular order
        EXPECT_TRUE(m.owner[f - 1] < m.owner[f] || (m.owner[f - 1] == m.owner[f] && m.neighbour[f - 1] < m.neighbour[f]));
      }
    }
  }
  // Each patch holds exactly the faces on its side of the cube, facing out.
  ASSERT_EQ(m.patches.size(), 6u);
  int next = m.internal_faces();
  for (int p = 0; p < 6; ++p) {
    const auto& patch = m.patches[p];
    EXPECT_EQ(patch.name, kNames[p]);
    EXPECT_EQ(patch.start, next);
    EXPECT_EQ(patch.size, 2 * n * n);
    next += patch.size;
    const int axis = p / 2;
    const double side = p % 2 ? n : 0.0, outward = p % 2 ? 1.0 : -1.0;
    for (int f = patch.start; f < patch.start + patch.size; ++f) {
      const auto& t = m.faces[f];
      for (int v : t) EXPECT_EQ(m.points[v][axis], side) << patch.name;
      const Eigen::Vector3d area = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]);
      EXPECT_GT(outward * area[axis], 0.0) << patch.name;
    }
  }
  // Volumes: 1/6 each, whatever the input orientation was.
  double total = 0.0;
  for (double v : cell_volumes(m)) {
    EXPECT_NEAR(v, 1.0 / 6.0, 1e-12);
    total += v;
  }
  EXPECT_NEAR(total, n * n * n, 1e-9);
}

TEST(PolyMesh, CellsAreNumberedBottomToTop) {
  Grid g = kuhn_grid(2);
  const PolyMesh m = poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes);
  const std::vector<Eigen::Vector3d> cc = cell_centres(m);
  for (int c = 1; c < m.cells; ++c) EXPECT_LE(cc[c - 1].z(), cc[c].z() + 1e-12);
}

TEST(PolyMesh, ABoundaryFaceInNoPatchIsNamedWithItsPlace) {
  Grid g = kuhn_grid(1);
  g.boundary.pop_back();
  g.patch.pop_back();
  EXPECT_THROW(poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes), std::runtime_error);
}

// One cell's faces, all on the boundary (owned by cell 0); the points do not matter here.
PolyMesh one_cell(std::vector<Face> faces) {
  PolyMesh m;
  m.cells = 1;
  m.owner.assign(faces.size(), 0);
  m.faces = std::move(faces);
  return m;
}

TEST(PolyMesh, APrismIsFoundAndAHexahedronOrTetrahedraAreNot) {
  EXPECT_TRUE(has_prisms(one_cell({{0, 1, 2}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}})));
  EXPECT_FALSE(has_prisms(
      one_cell({{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}})));
  const Grid g = kuhn_grid(2);
  EXPECT_FALSE(has_prisms(poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes)));
}

TEST(CellQuality, ARegularTetHasOpenFoamsIdealFigures) {
  // One regular tetrahedron: no internal faces; aspect ratio from projected areas and area/volume.
  const double s = 1.0;
  std::vector<Eigen::Vector3d> p{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  for (auto& x : p) x *= s;
  std::vector<std::array<int, 3>> b{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const PolyMesh m = poly_mesh_from_tets(p, {{0, 1, 2, 3}}, b, {0, 0, 0, 0}, {"all"}, {"wall"});
  const CellQuality q = cell_quality(m);
  // Regular tet of edge 2 sqrt(2): volume 8/3, every face of area 2 sqrt(3) with |n| components 1/sqrt(3).
  EXPECT_NEAR(q.volume[0], 8.0 / 3.0, 1e-12);
  const double face_area = 2.0 * std::sqrt(3.0);
  // checkMesh sums the area vectors' components: |Sx| + |Sy| + |Sz| = sqrt(3) x area here.
  EXPECT_NEAR(q.aspect_ratio[0], 4.0 * std::sqrt(3.0) * face_area / 6.0 / std::pow(8.0 / 3.0, 2.0 / 3.0), 1e-12);
  EXPECT_NEAR(q.max_skewness, 0.0, 1e-12);  // boundary skewness: the normal through the centre hits the face centre
}

TEST(CellQuality, AFlattenedTetIsCaughtByTheGate) {
  // Two tets sharing a face; lowering the apex of one makes the centre-to-centre line lean
  // against the shared face: non-orthogonality and aspect ratio both grow.
  auto pair = [](double h) {
    std::vector<Eigen::Vector3d> p{{0, 0, 0}, {1, 0, 0}, {0.5, 0.8660254, 0}, {0.5, 0.2886751, 0.8164966}, {20.0, 0.3, -h}};
    std::vector<std::array<int, 4>> t{{0, 1, 2, 3}, {0, 1, 2, 4}};
    std::vector<std::array<int, 3>> b{{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 1, 4}, {1, 2, 4}, {2, 0, 4}};
    return cell_quality(poly_mesh_from_tets(p, t, b, std::vector<int>(6, 0), {"all"}, {"wall"}));
  };
  const CellQuality good = pair(0.8), bad = pair(0.001);
  EXPECT_GT(bad.max_non_orthogonality_deg, good.max_non_orthogonality_deg);
  EXPECT_GT(bad.max_non_orthogonality_deg, 85.0);
  EXPECT_GT(bad.max_aspect_ratio, 10.0 * good.max_aspect_ratio);
  const QualityGate gate;
  EXPECT_FALSE(bad.bad_cells(gate, 1.0).empty());
}

TEST(CellQuality, AFaceTurnedIntoItsCellIsAnInvertedPyramid) {
  // A unit cube whose faces point out of it, then with one face turned inwards: its volume stays
  // positive (5/6 - 1/6), so only the face pyramid (checkMesh's check) sees the turned face.
  std::vector<Face> faces{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  auto cube = [](std::vector<Face> f) {
    PolyMesh m = one_cell(std::move(f));
    m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    return cell_quality(m);
  };
  const CellQuality good = cube(faces);
  EXPECT_NEAR(good.volume[0], 1.0, 1e-12);
  EXPECT_NEAR(good.min_face_pyramid[0], 1.0 / 6.0, 1e-12);  // each face with the centre: a sixth of the cube
  EXPECT_EQ(good.inverted_face_pyramids, 0);
  EXPECT_TRUE(good.bad_cells(QualityGate{}, 1.0).empty());
  std::reverse(faces[1].begin(), faces[1].end());
  const CellQuality turned = cube(faces);
  EXPECT_NEAR(turned.volume[0], 2.0 / 3.0, 1e-12);
  // OpenFOAM's centre weighs each face's pyramid from the faces' mean centre (z = 1/2), the
  // turned one negatively: z = (4 x 1/4 + 1/16 - 7/16) / 2 = 5/16; the top face's pyramid from
  // there is -(1 - 5/16) / 3.
  EXPECT_NEAR(turned.min_face_pyramid[0], -11.0 / 48.0, 1e-12);
  EXPECT_EQ(turned.inverted_face_pyramids, 1);
  EXPECT_EQ(turned.bad_cells(QualityGate{}, 1.0), std::vector<int>{0});
}

TEST(CellQuality, PolygonFacesGiveTheFiguresOfTheSameFacesStoredFixed) {
  // The same tetrahedra as a PolyMesh and as a PolyhedralMesh: every figure alike, cell by cell.
  Grid g = kuhn_grid(2);
  for (std::size_t v = 0; v < g.points.size(); ++v) g.points[v].x() += 0.1 * std::sin(3.0 * v);
  const PolyMesh m = poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes);
  PolyhedralMesh p;
  p.points = m.points, p.owner = m.owner, p.neighbour = m.neighbour, p.patches = m.patches, p.cells = m.cells;
  for (const Face& f : m.faces) p.faces.push_back(std::span<const int>(f.begin(), f.end()));
  const CellQuality a = cell_quality(m), b = cell_quality(p);
  EXPECT_EQ(a.non_orthogonality_deg, b.non_orthogonality_deg);
  EXPECT_EQ(a.skewness, b.skewness);
  EXPECT_EQ(a.aspect_ratio, b.aspect_ratio);
  EXPECT_EQ(a.volume, b.volume);
  EXPECT_EQ(a.min_face_pyramid, b.min_face_pyramid);
  EXPECT_GT(a.max_skewness, 0.0);  // the shaken grid is not regular
}

}  // namespace
}  // namespace bedforge::meshing
