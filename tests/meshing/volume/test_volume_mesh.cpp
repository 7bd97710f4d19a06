// gmsh volume meshes of small beds: the cells fill exactly the surface they were made from,
// every patch keeps its triangles, and a mesh failing the gate is located and written out.
#include "meshing/volume/volume_mesh.hpp"
#include "meshing/volume/gmsh_model.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <fstream>
#include <sstream>

#include "meshing/surface/fluid_surface.hpp"
#include "meshing/surface/surface_checks.hpp"
#include "support/cli.hpp"
#include "support/packed_bed.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::meshing;
namespace fs = std::filesystem;

namespace {

// Four spheres of d = 1 in a tube of a = 3.2: a column of three touching on the axis, one
// touching the middle one, 0.1 d from the wall.
Bed small_bed() {
  Bed b;
  b.container = std::make_shared<Cylinder>(1.6);
  for (int k = 0; k < 3; ++k) b.centres.emplace_back(0.0, 0.0, 0.5 + k), b.diameters.push_back(1.0);
  b.centres.emplace_back(0.0, 1.0, 1.5), b.diameters.push_back(1.0);
  return b;
}

FluidSurface coarse_surface(const Bed& b) {
  SurfaceParams p;
  p.edge_length_d = 0.2;
  p.contact_edge_length_d = 0.05;
  return build_fluid_surface(b, p);
}

// Every contact of `b`, walls included, treated by `t`; the default surface settings.
FluidSurface treated_surface(const Bed& b, SurfaceParams::Treatment t) {
  SurfaceParams p;
  p.treatment = p.wall_treatment = t;
  return build_fluid_surface(b, p);
}

fs::path scratch(const std::string& name) {
  return test_support::fresh_dir(name, true);
}

std::vector<int> patch_counts(const TriangleMesh& s, const PolyMesh& m) {
  std::vector<int> diff;
  for (const auto& p : m.patches) {
    const int k = static_cast<int>(std::find(s.patches.begin(), s.patches.end(), p.name) - s.patches.begin());
    diff.push_back(p.size - static_cast<int>(std::count(s.patch.begin(), s.patch.end(), k)));
  }
  return diff;
}

}  // namespace

TEST(VolumeMesh, CellsFillTheSurfaceAndKeepEveryPatch) {
  const Bed b = small_bed();
  const FluidSurface s = coarse_surface(b);
  const fs::path dir = scratch("fill");
  Progress quiet("mesh", false);
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, 1.0, {}, dir / "fluid.msh", dir / "bad_cells.vtk", quiet);
  // The tets' volume is the enclosed volume of the surface (same boundary triangles), to round-off.
  const double enclosed = check_surface(s.fluid, SelfIntersectionTest::skip).volume;
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);
  EXPECT_GT(vm.quality.min_volume, 0.0);
  // Every surface triangle is a boundary face of its own patch, none added or lost.
  ASSERT_EQ(vm.mesh.patches.size(), 4u);
  for (int d : patch_counts(s.fluid, vm.mesh)) EXPECT_EQ(d, 0);
  EXPECT_EQ(vm.mesh.patches[0].name, "inlet");
  EXPECT_EQ(vm.mesh.patches[3].type, "wall");
  EXPECT_LE(vm.quality.max_non_orthogonality_deg, QualityGate{}.max_non_orthogonality_deg);
  // What gmsh wrote reads back as the same mesh.
  const PolyMesh again = read_msh(dir / "fluid.msh");
  EXPECT_EQ(again.cells, vm.mesh.cells);
  EXPECT_EQ(again.faces.size(), vm.mesh.faces.size());
  EXPECT_FALSE(fs::exists(dir / "bad_cells.vtk"));
}

TEST(VolumeMesh, PrismLayersAndTetrahedraFillTheSurfaceTogether) {
  const Bed b = small_bed();
  const FluidSurface s = coarse_surface(b);
  const fs::path dir = scratch("layers");
  VolumeMeshParams p;
  p.layers.count = 3;
  p.layers.thickness_d = 0.02;
  Progress quiet("mesh", false);
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, 1.0, p, dir / "fluid.msh", dir / "bad_cells.vtk", quiet);
  // The layers and the tetrahedra above them fill exactly what the surface encloses, every cell
  // positive, and the particles keep their triangles (now the feet of the stacks).
  const double enclosed = check_surface(s.fluid, SelfIntersectionTest::skip).volume;
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);
  EXPECT_GT(vm.quality.min_volume, 0.0);
  for (int d : patch_counts(s.fluid, vm.mesh)) EXPECT_EQ(d, 0);
  const long prisms = vm.report["layers"]["cells"]["prisms"].get<long>();
  EXPECT_GT(prisms, 0);
  // Quads are the prisms' sides: each prism has three, shared with its neighbours in the stack
  // ring or lying on no boundary.
  long quads = 0;
  for (const auto& f : vm.mesh.faces) quads += f.size() == 4;
  EXPECT_GE(quads, 3 * prisms / 2);
  // What gmsh wrote reads back as the same mesh, layers included.
  const PolyMesh again = read_msh(dir / "fluid.msh");
  EXPECT_EQ(again.cells, vm.mesh.cells);
  EXPECT_EQ(again.faces.size(), vm.mesh.faces.size());
  EXPECT_NEAR(cell_quality(again).total_volume, enclosed, 1e-9 * enclosed);
}

// Issue 57's bed (a = 4, N = 40, seed 1, bridges) at the coarsest level of a layered study (edge
// 0.283 d, 2 layers of 0.0227 d): gmsh's renumbering of the nodes after meshing shuffled the
// surface's tags there, and every algorithm failed to join the layers (2026-12-07).
TEST(VolumeMesh, PrismLayersJoinACoarseBridgedBed) {
  // In metres, d = 3 mm, as a scene has it: at d = 1 m the same bed met no renumbering.
  const double d = 0.003;
  Bed b = test_support::packed_bed(40, 4.0, 1);
  for (auto& c : b.centres) c *= d;
  for (auto& x : b.diameters) x *= d;
  b.container = std::make_shared<Cylinder>(2.0 * d);
  SurfaceParams sp;
  sp.treatment = sp.wall_treatment = SurfaceParams::Treatment::bridge;
  sp.edge_length_d = 0.28324;
  sp.contact_edge_length_d = 0.081947;
  sp.cells_per_gap = 2.11864;
  const FluidSurface s = build_fluid_surface(b, sp);
  VolumeMeshParams p;
  p.max_size_d = 0.47206;
  p.layers.count = 2;
  p.layers.thickness_d = 0.022659;
  Progress quiet("mesh", false);
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, d, p, {}, {}, quiet);
  EXPECT_GT(vm.report["layers"]["cells"]["prisms"].get<long>(), 0);
  const double enclosed = check_surface(s.fluid, SelfIntersectionTest::skip).volume;
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);
}

TEST(VolumeMesh, AMeshBelowTheGateIsLocatedAndWrittenForParaView) {
  const Bed b = small_bed();
  const FluidSurface s = coarse_surface(b);
  const fs::path dir = scratch("gate");
  VolumeMeshParams p;
  p.gate.max_non_orthogonality_deg = 5.0;  // no tetrahedral mesh meets this
  Progress quiet("mesh", false);
  try {
    build_volume_mesh(s.fluid, b, 1.0, p, dir / "fluid.msh", dir / "bad_cells.vtk", quiet);
    FAIL() << "a gate of 5 degrees passed";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("hxt"), std::string::npos) << msg;       // both algorithms were tried,
    EXPECT_NE(msg.find("delaunay"), std::string::npos) << msg;  // the fallback last
    EXPECT_NE(msg.find("near particle"), std::string::npos) << msg;
    EXPECT_NE(msg.find("bad_cells.vtk"), std::string::npos) << msg;
  }
  std::ifstream vtk(dir / "bad_cells.vtk");
  std::stringstream text;
  text << vtk.rdbuf();
  EXPECT_NE(text.str().find("DATASET POLYDATA"), std::string::npos);
  EXPECT_NE(text.str().find("SCALARS nearest_particle"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "fluid.msh"));
}

// A retry (HXT's own optimiser, gmsh's Delaunay) takes about 1500 bytes per cell: where that
// would not fit in what this process may take (here one of a billion ranks on this machine,
// OMPI_COMM_WORLD_LOCAL_SIZE, as under mpirun), it is skipped and said; the control, the same
// command as one process, tries both.
TEST(VolumeMesh, ARetryThatWouldNotFitInARanksShareOfTheMachineIsSkippedAndSaid) {
  const fs::path dir = cli_test::fresh_dir("retry_share");
  const std::string bedforge = std::string(BEDFORGE_BINARY) + " --quiet ";
  ASSERT_EQ(cli_test::shell(bedforge + "pack --aspect-ratio 3 --count 12 --diameter-m 0.002 -o " + dir.string() +
                            " && " + bedforge + "surface " + dir.string() + " --edge-length-d 0.25")
                .status,
            0);
  const std::string mesh = bedforge + "mesh " + dir.string() + " --max-non-orthogonality 5";  // no mesh passes
  const cli_test::Result rank = cli_test::shell("OMPI_COMM_WORLD_LOCAL_SIZE=1000000000 " + mesh);
  EXPECT_EQ(rank.status, 3) << rank.output;
  EXPECT_NE(rank.output.find("hxt (its own optimiser) skipped: it would need about"), std::string::npos) << rank.output;
  EXPECT_NE(rank.output.find("delaunay skipped: it would need about"), std::string::npos) << rank.output;
  const cli_test::Result alone = cli_test::shell(mesh);
  EXPECT_EQ(alone.status, 3) << alone.output;
  EXPECT_EQ(alone.output.find("skipped"), std::string::npos) << alone.output;
  EXPECT_NE(alone.output.find("delaunay: "), std::string::npos) << alone.output;
}

// Enlarged contacts leave fluid wedges of about 16 degrees around each neck, where gmsh's
// optimiser passes left a few slivers on every enlarged bed tried (this packing at d = 3 mm:
// 7 of 360 k cells over the aspect-ratio limit of 1000, at 89f157a); HXT's own optimisation,
// the retry, clears them.
TEST(VolumeMesh, AnEnlargedBedPassesTheGateWithHxtsOwnOptimiser) {
  Progress quiet("mesh", false);
  const Bed b = test_support::packed_bed(80, 4.0, 1);
  const FluidSurface s = treated_surface(b, SurfaceParams::Treatment::enlarge);
  const fs::path dir = scratch("enlarge");
  VolumeMeshParams p;
  p.fallback = false;  // HXT alone: the retry with its own optimiser is part of `optimize`
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, 1.0, p, dir / "fluid.msh", dir / "bad_cells.vtk", quiet);
  EXPECT_TRUE(vm.quality.bad_cells(p.gate, 1.0).empty());
  // The premise: gmsh's passes alone left cells over the gate, so the retry was needed.
  ASSERT_EQ(vm.report["attempts"].size(), 2u);
  EXPECT_GT(vm.report["attempts"][0]["cells_failing_gate"].get<long>(), 0);
  EXPECT_EQ(vm.report["optimiser"], "hxt");
  // The first attempt's bad cells no longer describe the mesh written.
  EXPECT_FALSE(fs::exists(dir / "bad_cells.vtk"));
  const double enclosed = check_surface(s.fluid, SelfIntersectionTest::skip).volume;
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);
}

// Facing cap disks laid out alike put four surface points in a plane across every cap's gap,
// and HXT's first mesh of this bed then failed the gate (docs/findings.md, session 34). With the
// second disk turned by half a rim step the first attempt passes.
TEST(VolumeMesh, ACappedBedPassesTheGateAtTheFirstAttempt) {
  Progress quiet("mesh", false);
  const Bed b = test_support::packed_bed(80, 4.0, 1);
  const FluidSurface s = treated_surface(b, SurfaceParams::Treatment::cap);
  VolumeMeshParams p;
  p.fallback = false;
  p.threads = 1;  // as the check without the turn ran it (2 attempts there)
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, 1.0, p, {}, {}, quiet);
  EXPECT_TRUE(vm.quality.bad_cells(p.gate, 1.0).empty());
  EXPECT_EQ(vm.report["attempts"].size(), 1u) << vm.report["attempts"].dump();
  EXPECT_EQ(vm.report["optimiser"], "gmsh");
}

TEST(VolumeMesh, AnAnnulusMeshesWithItsInnerWall) {
  Bed b;
  b.container = std::make_shared<Annulus>(2.0, 0.75);
  for (int k = 0; k < 4; ++k) {
    const double t = k * 1.5707963267948966;
    b.centres.emplace_back(1.375 * std::cos(t), 1.375 * std::sin(t), 0.5 + 0.4 * k);
    b.diameters.push_back(1.0);
  }
  const FluidSurface s = coarse_surface(b);
  Progress quiet("mesh", false);
  const VolumeMesh vm = build_volume_mesh(s.fluid, b, 1.0, {}, {}, {}, quiet);
  for (int d : patch_counts(s.fluid, vm.mesh)) EXPECT_EQ(d, 0);
  const double enclosed = check_surface(s.fluid, SelfIntersectionTest::skip).volume;
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);
}

namespace {
// The distinct point indices of each cell of `m`.
std::vector<std::vector<int>> cell_points(const PolyMesh& m) {
  std::vector<std::vector<int>> cells(m.cells);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int c : {m.owner[f], f < m.neighbour.size() ? m.neighbour[f] : -1}) {
      if (c < 0) continue;
      for (int v : m.faces[f])
        if (std::find(cells[c].begin(), cells[c].end(), v) == cells[c].end()) cells[c].push_back(v);
    }
  return cells;
}

// Longest piece of the segment a-b inside one cell of `m`, as a fraction of the segment, from
// 1000 points along it; `cells` lists the candidates (their points).
double longest_piece_in_a_cell(const PolyMesh& m, const std::vector<std::vector<int>>& cells,
                               const std::vector<int>& candidates, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  std::map<int, int> samples;  // per cell crossed
  constexpr int kSamples = 1000;
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector3d x = a + (b - a) * ((k + 0.5) / kSamples);
    for (int c : candidates) {
      Eigen::Matrix3d e;
      for (int j = 0; j < 3; ++j) e.col(j) = m.points[cells[c][j + 1]] - m.points[cells[c][0]];
      const Eigen::Vector3d l = e.inverse() * (x - m.points[cells[c][0]]);
      if (l.minCoeff() >= 0.0 && l.sum() <= 1.0) {
        ++samples[c];
        break;
      }
    }
  }
  int most = 0;
  for (const auto& [cell, n] : samples) most = std::max(most, n);
  return static_cast<double>(most) / kSamples;
}

// The mean over a bundle of 25 segments parallel to a-b (offsets up to `spread` across it, in
// y and z) of the longest piece of each inside one cell: one line's value depends on where a
// vertex happens to fall, the bundle's mean much less.
double mean_longest_piece(const PolyMesh& m, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double spread) {
  const std::vector<std::vector<int>> cells = cell_points(m);
  Eigen::AlignedBox3d near(a.cwiseMin(b), a.cwiseMax(b));
  near.min() -= Eigen::Vector3d(0.0, spread, spread);
  near.max() += Eigen::Vector3d(0.0, spread, spread);
  std::vector<int> candidates;
  for (int c = 0; c < m.cells; ++c) {
    Eigen::AlignedBox3d box;
    for (int v : cells[c]) box.extend(m.points[v]);
    if (box.intersects(near)) candidates.push_back(c);
  }
  double sum = 0.0;
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j) {
      const Eigen::Vector3d o(0.0, 0.5 * spread * i, 0.5 * spread * j);
      sum += longest_piece_in_a_cell(m, cells, candidates, a + o, b + o);
    }
  return sum / 25.0;
}
}  // namespace

TEST(VolumeMesh, CellsPerGapPutsThatManyCellsAcrossAGap) {
  // Two spheres of d = 1, 0.1 d apart, in a tube of a = 3.2; no contact treatment.
  Bed b;
  b.container = std::make_shared<Cylinder>(1.6);
  b.centres = {{-0.55, 0.0, 0.6}, {0.55, 0.0, 0.6}};
  b.diameters = {1.0, 1.0};
  SurfaceParams sp;
  sp.treatment = sp.wall_treatment = SurfaceParams::Treatment::none;
  sp.edge_length_d = 0.2;
  sp.contact_edge_length_d = 0.01;
  Progress quiet("mesh", false);
  // Along the line of centres, from one sphere's surface to the other's.
  const Eigen::Vector3d from(-0.05, 0.0, 0.6), to(0.05, 0.0, 0.6);
  // The default threads, as users run it: HXT's graded mesh then changes from run to run, so
  // the measure is a bundle's mean rather than one line's (which reached 0.33 in 1 of 6 runs).
  const VolumeMeshParams mp;
  const VolumeMesh plain = build_volume_mesh(build_fluid_surface(b, sp).fluid, b, 1.0, mp, {}, {}, quiet);
  sp.cells_per_gap = 4.0;
  const VolumeMesh graded = build_volume_mesh(build_fluid_surface(b, sp).fluid, b, 1.0, mp, {}, {}, quiet);
  const double piece_plain = mean_longest_piece(plain.mesh, from, to, 0.06);
  const double piece = mean_longest_piece(graded.mesh, from, to, 0.06);
  // A quarter asked for, gmsh's sizes within about 1.3 x: at most a third. 32 runs on 2 threads
  // (2026-11-24) gave 0.206-0.240 graded and 0.59 plain, so both bounds hold with room.
  EXPECT_LE(piece, 1.0 / 3.0);
  EXPECT_GT(piece_plain, 1.5 * piece) << "plain " << piece_plain << ", graded " << piece;
}
