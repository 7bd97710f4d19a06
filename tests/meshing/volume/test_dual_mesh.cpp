#include "meshing/volume/dual_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>

#include "cases/poly_mesh_io.hpp"
#include "support/cli.hpp"
#include "support/tet_grid.hpp"

namespace bedforge::meshing {
namespace {

// Moves the points of an n^3 box that are not on its sides by up to `by` (deterministic), so that
// no cell of the dual is a regular one.
void shake(std::vector<Eigen::Vector3d>& points, int n, double by) {
  for (std::size_t v = 0; v < points.size(); ++v) {
    Eigen::Vector3d& x = points[v];
    if (x.minCoeff() > 0.0 && x.maxCoeff() < n)
      x += by * Eigen::Vector3d(std::sin(7.1 * v), std::sin(3.7 * v + 1.0), std::sin(5.3 * v + 2.0));
  }
}

// An n^3 box of Kuhn tetrahedra, shaken.
PolyMesh shaken_box(int n) {
  Grid g = kuhn_grid(n);
  shake(g.points, n, 0.2);
  return poly_mesh_from_tets(g.points, g.tets, g.boundary, g.patch, kNames, kTypes);
}

// An n^3 box of prisms (each cube cut in two along its xy diagonal), shaken: the cells of prism
// layers, with quadrilateral faces.
PolyMesh shaken_prisms(int n) {
  Grid g = kuhn_grid(n);
  shake(g.points, n, 0.1);
  auto id = [n](int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; };
  std::vector<VolumeCell> cells;
  std::vector<Face> boundary;
  std::vector<int> patch;
  auto on_side = [&](const Face& f) {
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side)
        if (std::all_of(f.begin(), f.end(), [&](int v) { return g.points[v][axis] == side * n; })) return 2 * axis + side;
    return -1;
  };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& t : {std::array<int, 3>{id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k)},
                              std::array<int, 3>{id(i, j, k), id(i + 1, j + 1, k), id(i, j + 1, k)}}) {
          const int up = (n + 1) * (n + 1);
          VolumeCell c{{t[0], t[1], t[2], t[0] + up, t[1] + up, t[2] + up}, 6};
          cells.push_back(c);
          for (const Face& f : {Face{t[0], t[1], t[2]}, Face{t[0] + up, t[1] + up, t[2] + up},
                                Face{t[0], t[1], t[1] + up, t[0] + up}, Face{t[1], t[2], t[2] + up, t[1] + up},
                                Face{t[2], t[0], t[0] + up, t[2] + up}})
            if (const int side = on_side(f); side >= 0) boundary.push_back(f), patch.push_back(side);
        }
  return poly_mesh_from_cells(g.points, cells, boundary, patch, kNames, kTypes);
}

// Closed cells of positive volume that fill the n^3 box, one per point of `m`, in OpenFOAM's
// face order, with patches on the box's sides.
void expect_dual_fills_box(const PolyMesh& m, int n) {
  const PolyhedralMesh d = dual_mesh(m, cell_centres(m), 80.0);
  ASSERT_EQ(d.cells, static_cast<int>(m.points.size()));
  // Closed cells: the outward area vectors of each cell's faces sum to zero.
  std::vector<Eigen::Vector3d> closure(d.cells, Eigen::Vector3d::Zero());
  std::vector<double> area(d.cells, 0.0);
  for (int f = 0; f < static_cast<int>(d.faces.size()); ++f) {
    const Eigen::Vector3d a = face_geometry(d.points, d.faces[f]).area;
    closure[d.owner[f]] += a, area[d.owner[f]] += a.norm();
    if (f < d.internal_faces()) closure[d.neighbour[f]] -= a, area[d.neighbour[f]] += a.norm();
  }
  for (int c = 0; c < d.cells; ++c) EXPECT_LT(closure[c].norm(), 1e-12 * area[c]) << "cell " << c;
  // Every cell has a positive volume and together they fill the box exactly: the dual's boundary
  // keeps the box's flat sides, its edges and corners (feature edges and points at 90 > 80 deg).
  const CellGeometry cg = cell_geometry(d);
  double total = 0.0;
  for (double v : cg.volumes) {
    EXPECT_GT(v, 0.0);
    total += v;
  }
  EXPECT_NEAR(total, n * n * n, 1e-10);
  // Internal faces in upper-triangular order, each facing from its owner's centre to its
  // neighbour's.
  for (int f = 0; f < d.internal_faces(); ++f) {
    EXPECT_LT(d.owner[f], d.neighbour[f]);
    if (f > 0) {
      EXPECT_TRUE(d.owner[f - 1] < d.owner[f] || (d.owner[f - 1] == d.owner[f] && d.neighbour[f - 1] <= d.neighbour[f]))
          << "face " << f;
    }
    EXPECT_GT(face_geometry(d.points, d.faces[f]).area.dot(cg.centres[d.neighbour[f]] - cg.centres[d.owner[f]]), 0.0)
        << "face " << f;
  }
  // Each patch lies on its side of the box, faces out and covers it.
  ASSERT_EQ(d.patches.size(), 6u);
  EXPECT_EQ(d.patches[0].start, d.internal_faces());
  for (int p = 0; p < 6; ++p) {
    const auto& patch = d.patches[p];
    EXPECT_EQ(patch.name, kNames[p]);
    if (p > 0) {
      EXPECT_EQ(patch.start, d.patches[p - 1].start + d.patches[p - 1].size);
    }
    const int axis = p / 2;
    const double side = p % 2 ? n : 0.0, outward = p % 2 ? 1.0 : -1.0;
    double covered = 0.0;
    for (int f = patch.start; f < patch.start + patch.size; ++f) {
      for (int v : d.faces[f]) EXPECT_NEAR(d.points[v][axis], side, 1e-12) << patch.name;
      covered += outward * face_geometry(d.points, d.faces[f]).area[axis];
    }
    EXPECT_NEAR(covered, n * n, 1e-10) << patch.name;
  }
  EXPECT_EQ(d.patches.back().start + d.patches.back().size, static_cast<int>(d.faces.size()));
}

TEST(DualMesh, ItsCellsAreClosedAndFillTheBoxOnePerPoint) { expect_dual_fills_box(shaken_box(4), 4); }

TEST(DualMesh, OfPrismsTooItsCellsAreClosedAndFillTheBox) { expect_dual_fills_box(shaken_prisms(3), 3); }

// At a feature point the quadrilaterals of a patch's faces that lie in one plane are one face:
// on the box every cell has at most one face per side (at an edge or corner of the box too);
// kept apart, as polyDualMesh keeps them, the cells at the box's edges have several.
TEST(DualMesh, AFeaturePointsFacesInOnePlaneAreOneFace) {
  const PolyMesh m = shaken_box(4);
  for (bool join : {true, false}) {
    const PolyhedralMesh d = dual_mesh(m, cell_centres(m), 80.0, nullptr, join);
    std::map<std::pair<int, int>, int> faces;  // (cell, patch) -> faces
    for (int k = 0; k < static_cast<int>(d.patches.size()); ++k)
      for (int f = d.patches[k].start; f < d.patches[k].start + d.patches[k].size; ++f) ++faces[{d.owner[f], k}];
    int most = 0;
    for (const auto& [key, count] : faces) most = std::max(most, count);
    if (join) {
      EXPECT_EQ(most, 1);
    } else {
      EXPECT_GT(most, 1);
    }
  }
}

// checkMesh's counts and geometry figures of the case in `dir`, as numbers in the order
// printed: the mesh's statistics, the patch table, and the cells' volumes, areas and quality.
std::vector<double> check_mesh_figures(const std::filesystem::path& dir) {
  const cli_test::Result r =
      cli_test::shell("cd " + dir.string() + " && WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam} checkMesh");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("Mesh OK."), std::string::npos) << r.output;
  const std::regex wanted(
      R"(^\s+(points:|faces:|internal faces:|cells:|boundary patches:|polyhedra:|x0 |x1 |y0 |y1 |z0 |z1 |Max aspect ratio|Minimum face area|Min volume|Mesh non-orthogonality|Max skewness))");
  const std::regex number(R"([-+]?\d+(\.\d+)?([eE][-+]?\d+)?)");
  std::vector<double> figures;
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) {
    if (!std::regex_search(line, wanted)) continue;
    for (std::sregex_iterator it(line.begin(), line.end(), number), end; it != end; ++it)
      figures.push_back(std::stod(it->str()));
  }
  return figures;
}

void write_case(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "system");
  std::ofstream(dir / "system/controlDict")
      << cases::foam_header("dictionary", "system", "controlDict", "test")
      << "application simpleFoam;\nstartFrom startTime;\nstartTime 0;\nstopAt endTime;\nendTime 1;\n"
         "deltaT 1;\nwriteControl timeStep;\nwriteInterval 1;\nwriteFormat binary;\nwritePrecision 17;\n";
  // polyDualMesh reads the schemes and solution controls, though it uses none.
  std::ofstream(dir / "system/fvSchemes") << cases::foam_header("dictionary", "system", "fvSchemes", "test")
                                          << "ddtSchemes {}\ngradSchemes {}\ndivSchemes {}\nlaplacianSchemes {}\n"
                                             "interpolationSchemes {}\nsnGradSchemes {}\n";
  std::ofstream(dir / "system/fvSolution") << cases::foam_header("dictionary", "system", "fvSolution", "test");
}

// The dual is the one OpenFOAM's polyDualMesh makes from the same tetrahedra: checkMesh counts
// the same points, faces and cells, the same faces per patch, and measures the same volumes, face
// areas, non-orthogonality and skewness (to one unit of the sixth digit it prints).
void expect_polydualmesh_agrees(const PolyMesh& m) {
  const auto theirs = cli_test::fresh_dir("dual_theirs"), ours = cli_test::fresh_dir("dual_ours");
  write_case(theirs);
  write_case(ours);
  cases::write_poly_mesh(theirs / "constant/polyMesh", m, true, "test");
  cases::write_poly_mesh(ours / "constant/polyMesh", dual_mesh(m, cell_centres(m), 80.0, nullptr, false), true, "test");
  const cli_test::Result r = cli_test::shell("cd " + theirs.string() +
                                             " && WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam} "
                                             "polyDualMesh -overwrite 80");
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<double> expected = check_mesh_figures(theirs), got = check_mesh_figures(ours);
  ASSERT_EQ(got.size(), expected.size());
  ASSERT_GT(got.size(), 20u);
  for (std::size_t k = 0; k < got.size(); ++k)
    EXPECT_NEAR(got[k], expected[k], 1e-5 * std::abs(expected[k])) << "figure " << k;
}

// A figure checkMesh prints after `label` (e.g. "Max skewness = ") in the case in `dir`.
double check_mesh_figure(const std::filesystem::path& dir, const std::string& label) {
  const cli_test::Result r =
      cli_test::shell("cd " + dir.string() + " && WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam} checkMesh");
  const auto at = r.output.find(label);
  if (at == std::string::npos) throw std::runtime_error("checkMesh printed no `" + label + "`:\n" + r.output);
  return std::stod(r.output.substr(at + label.size()));
}

TEST(DualMesh, ItsQualityIsTheOneCheckMeshMeasures) {
  // The figures bedforge gates a case's polyhedra by are checkMesh's own, on the same cells (to
  // the sixth digit it prints).
  if (cli_test::shell("command -v checkMesh").status != 0) GTEST_SKIP() << "OpenFOAM (checkMesh) not on PATH";
  const PolyMesh m = shaken_box(4);
  const PolyhedralMesh dual = dual_mesh(m, cell_centres(m), 80.0);
  const auto dir = cli_test::fresh_dir("dual_quality");
  write_case(dir);
  cases::write_poly_mesh(dir / "constant/polyMesh", dual, true, "test");
  const CellQuality q = cell_quality(dual);
  EXPECT_NEAR(q.max_skewness, check_mesh_figure(dir, "Max skewness = "), 1e-5 * q.max_skewness);
  EXPECT_NEAR(q.max_non_orthogonality_deg, check_mesh_figure(dir, "Mesh non-orthogonality Max: "),
              1e-5 * q.max_non_orthogonality_deg);
  EXPECT_NEAR(q.max_aspect_ratio, check_mesh_figure(dir, "Max aspect ratio = "), 1e-5 * q.max_aspect_ratio);
  EXPECT_NEAR(q.min_volume, check_mesh_figure(dir, "Min volume = "), 1e-5 * q.min_volume);
  EXPECT_GT(q.max_skewness, 0.1);  // the shaken box's dual is far from regular
}

// One hexahedral cell on the points given (0-3 the bottom, 4-7 above them), its six faces one
// wall patch; `top` its top face, pointing out of the cell unless given turned.
PolyhedralMesh one_hexahedron(std::vector<Eigen::Vector3d> points, const std::vector<int>& top = {4, 5, 6, 7}) {
  PolyhedralMesh cell;
  cell.points = std::move(points);
  for (const std::vector<int>& f : std::vector<std::vector<int>>{
           {0, 3, 2, 1}, top, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}})
    cell.faces.push_back(f);
  cell.owner.assign(6, 0);
  PolyMesh::Patch walls;
  walls.name = "walls", walls.type = "wall", walls.size = 6;
  cell.patches = {walls};
  cell.cells = 1;
  return cell;
}

TEST(DualMesh, ABoundaryFacesSkewnessIsTheOneCheckMeshMeasures) {
  // A 1 x 1 x 10 box whose top is shifted by 1 in x: its end faces' centres sit 0.5 beside the
  // normal through the cell's centre (1, 0.5, 5), 5 away. checkMesh normalises a boundary face's
  // offset by 0.4 of that distance (an internal face's by 0.2 of the two cells' distance):
  // 0.5 / max(0.4 x 5, the face's half-width 0.5) = 0.25.
  const PolyhedralMesh cell = one_hexahedron({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                              {1, 0, 10}, {2, 0, 10}, {2, 1, 10}, {1, 1, 10}});
  EXPECT_NEAR(cell_quality(cell).max_skewness, 0.25, 1e-12);
  if (cli_test::shell("command -v checkMesh").status != 0) GTEST_SKIP() << "OpenFOAM (checkMesh) not on PATH";
  const auto dir = cli_test::fresh_dir("boundary_skewness");
  write_case(dir);
  cases::write_poly_mesh(dir / "constant/polyMesh", cell, true, "test");
  EXPECT_NEAR(check_mesh_figure(dir, "Max skewness = "), 0.25, 1e-6);
}

TEST(DualMesh, PolyhedraFailingCheckMeshsLimitsAreSaidWhereJudged) {
  // One cube with a face turned into it (an inverted face pyramid, as checkMesh reports it; its
  // size, -11/48, is derived in test_poly_mesh.cpp).
  PolyhedralMesh cube = one_hexahedron(
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, {7, 6, 5, 4});
  Bed bed;
  bed.centres = {Eigen::Vector3d(0.5, 0.5, 2.0)};
  bed.diameters = {1.0};
  const auto dir = cli_test::fresh_dir("dual_gate");
  std::filesystem::create_directories(dir);
  const auto vtk = dir / "bad_polyhedra.vtk";
  const JudgedQuality q = check_polyhedra(cube, {}, nullptr, bed, 1.0, "the cube's polyhedra", vtk);
  EXPECT_EQ(q.failing_cells, 1);
  for (const char* said : {"the cube's polyhedra: 1 of 1 cells", "smallest face pyramid -2.29e-01 d^3, limit -1.00e-15",
                           "particle 0", "bad_polyhedra.vtk"})
    EXPECT_NE(q.failure.find(said), std::string::npos) << said << " not in: " << q.failure;
  EXPECT_TRUE(std::filesystem::exists(vtk));
  // A cell not judged (a neighbour's, around a piece) does not fail the piece; the stale file goes.
  EXPECT_EQ(check_polyhedra(cube, {false}, nullptr, bed, 1.0, "the cube's polyhedra", vtk).cells, 0);
  EXPECT_FALSE(std::filesystem::exists(vtk));
}

// checkMesh fails a face pyramid below -SMALL = -1e-15 m^3 whatever the cell's size, so the same
// turned cube (its pyramid -11/48 of its volume) passes at 10 um (-2.3e-16 m^3) and fails at
// 100 um (-2.3e-13 m^3).
TEST(DualMesh, AFacePyramidFailsBelowCheckMeshsAbsoluteLimit) {
  Bed bed;
  bed.centres = {Eigen::Vector3d(0.5, 0.5, 2.0)};
  bed.diameters = {1.0};
  const auto dir = cli_test::fresh_dir("dual_pyramid_limit");
  std::filesystem::create_directories(dir);
  for (const double size : {1e-5, 1e-4}) {
    std::vector<Eigen::Vector3d> corners{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (auto& c : corners) c *= size;
    PolyhedralMesh cube = one_hexahedron(corners, {7, 6, 5, 4});
    const JudgedQuality q = check_polyhedra(cube, {}, nullptr, bed, size, "the cube", dir / "bad.vtk");
    EXPECT_NEAR(q.min_face_pyramid, -11.0 / 48.0 * size * size * size, 1e-3 * size * size * size);
    EXPECT_EQ(q.failing_cells, size < 5e-5 ? 0 : 1) << size << " m: " << q.failure;
  }
}

TEST(DualMesh, PiecesJudgedApartAddUpToOneMeshsFigures) {
  // Two pieces' figures, as each rank writes them to its bedforge_piece.json and the case reads
  // them back (d = 2 mm, so volumes go through d^3): counts add, the worst of each figure stays.
  const double d = 0.002, d3 = d * d * d;
  const JudgedQuality one{100, 2, 1, 95.0, 3.0, 20.0, 1e-3 * d3, -1e-6 * d3, "piece 1 of 2's polyhedra: ...", 1};
  const JudgedQuality two{50, 0, 0, 60.0, 4.5, 10.0, 1e-4 * d3, 1e-5 * d3, "", 2};
  JudgedQuality both = JudgedQuality::from_json(one.to_json(d), d);
  EXPECT_EQ(both.to_json(d), one.to_json(d));
  both.add(JudgedQuality::from_json(two.to_json(d), d));
  EXPECT_EQ(both.cells, 150);
  EXPECT_EQ(both.merged_cells, 2);
  EXPECT_EQ(both.ears_cut, 3);
  EXPECT_EQ(both.failing_cells, 1);
  EXPECT_EQ(both.max_non_orthogonality_deg, 95.0);
  EXPECT_EQ(both.max_skewness, 4.5);
  EXPECT_EQ(both.max_aspect_ratio, 20.0);
  EXPECT_NEAR(both.min_volume, 1e-4 * d3, 1e-12 * d3);
  EXPECT_NEAR(both.min_face_pyramid, -1e-6 * d3, 1e-12 * d3);
  EXPECT_EQ(both.failure, one.failure);
}

TEST(DualMesh, TwoCellsAcrossAFailingFaceAreMergedIntoOneThatPasses) {
  // Two unit cubes side by side whose shared face (x = 1) points from the second into the first:
  // seen from the wrong side by both (non-orthogonality 180 deg, both pyramids inverted). Merged,
  // they are the 2 x 1 x 1 box, which passes; not judged, the second may not merge, and the face
  // fails the gate.
  auto two_cubes = [] {
    PolyhedralMesh m;
    for (int z = 0; z < 2; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) m.points.emplace_back(x, y, z);
    const auto p = [](int x, int y, int z) { return (z * 2 + y) * 3 + x; };
    m.faces.push_back(std::vector<int>{p(1, 0, 0), p(1, 0, 1), p(1, 1, 1), p(1, 1, 0)});  // normal -x: turned
    m.owner = {0};
    m.neighbour = {1};
    for (int c = 0; c < 2; ++c) {  // each cube's five outer faces, pointing out
      const std::vector<std::vector<int>> outer{
          {p(c, 0, 0), p(c, 1, 0), p(c + 1, 1, 0), p(c + 1, 0, 0)},   // z = 0
          {p(c, 0, 1), p(c + 1, 0, 1), p(c + 1, 1, 1), p(c, 1, 1)},   // z = 1
          {p(c, 0, 0), p(c + 1, 0, 0), p(c + 1, 0, 1), p(c, 0, 1)},   // y = 0
          {p(c, 1, 0), p(c, 1, 1), p(c + 1, 1, 1), p(c + 1, 1, 0)}};  // y = 1
      for (const auto& f : outer) m.faces.push_back(f), m.owner.push_back(c);
      const int x = 2 * c;  // the cube's end: x = 0 for the first, x = 2 for the second
      m.faces.push_back(c == 0 ? std::vector<int>{p(x, 0, 0), p(x, 0, 1), p(x, 1, 1), p(x, 1, 0)}
                               : std::vector<int>{p(x, 0, 0), p(x, 1, 0), p(x, 1, 1), p(x, 0, 1)});
      m.owner.push_back(c);
    }
    PolyMesh::Patch walls;
    walls.name = "walls", walls.type = "wall", walls.start = 1, walls.size = 10;
    m.patches = {walls};
    m.cells = 2;
    return m;
  };
  Bed bed;
  bed.centres = {Eigen::Vector3d(1.0, 0.5, 2.0)};
  bed.diameters = {1.0};
  const auto dir = cli_test::fresh_dir("dual_merge");
  std::filesystem::create_directories(dir);
  PolyhedralMesh merged = two_cubes();
  std::vector<int> cell_points{7, 9};
  const JudgedQuality q = check_polyhedra(merged, {}, &cell_points, bed, 1.0, "two cubes", dir / "bad.vtk");
  EXPECT_EQ(q.merged_cells, 1);
  EXPECT_EQ(q.failing_cells, 0);
  EXPECT_EQ(q.cells, 1);
  EXPECT_EQ(merged.cells, 1);
  EXPECT_EQ(merged.internal_faces(), 0);
  EXPECT_EQ(merged.faces.size(), 10u);
  EXPECT_EQ(merged.points.size(), 12u);  // the removed face's points are all on the others
  EXPECT_EQ(cell_points, std::vector<int>{7});
  EXPECT_NEAR(cell_geometry(merged).volumes[0], 2.0, 1e-12);
  EXPECT_GT(q.min_face_pyramid, 0.0);
  PolyhedralMesh kept = two_cubes();
  EXPECT_EQ(check_polyhedra(kept, {true, false}, nullptr, bed, 1.0, "two cubes", dir / "bad.vtk").failing_cells, 1);
  EXPECT_EQ(kept.cells, 2);
}

TEST(DualMesh, IsTheOnePolyDualMeshMakes) {
  if (cli_test::shell("command -v polyDualMesh").status != 0) GTEST_SKIP() << "OpenFOAM (polyDualMesh) not on PATH";
  expect_polydualmesh_agrees(shaken_box(4));
  expect_polydualmesh_agrees(shaken_prisms(3));
}

}  // namespace
}  // namespace bedforge::meshing
