// The polyhedral dual in pieces: three slabs of a bed, meshed each on its own, each given its
// neighbours' layers of tetrahedra next to their shared planes, make duals whose cells together
// are the cells of the whole mesh's dual (one per point, volume for volume), and whose processor
// patches match face for face, point for point (bit for bit), each face pointing out of its own
// piece's cell with a positive pyramid on both sides and the two pieces' centres across it
// within the quality gate's non-orthogonality.
#include "meshing/volume/dual_pieces.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <stdexcept>

#include "core/error.hpp"
#include "meshing/volume/cell_quality.hpp"
#include "meshing/volume/dual_mesh.hpp"
#include "meshing/volume/slab_mesh.hpp"
#include "support/packed_bed.hpp"
#include "support/processor_faces.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::meshing;

namespace {

struct Pieces {
  std::vector<PolyMesh> slabs;
  std::vector<PlaneLayer> inlet, outlet;  // each slab's layers (empty where no neighbour)
};

Pieces three_slabs() {
  const Bed b = test_support::packed_bed(60, 4.0, 2);
  SurfaceParams sp;  // shrink
  sp.edge_length_d = 0.25;
  const auto dir = test_support::fresh_dir("dual_pieces", true);
  Pieces p;
  for (int k = 0; k < 3; ++k) {
    p.slabs.push_back(mesh_slab(b, sp, slab_planes_d(b, sp, 3), k, 1.0, VolumeMeshParams{}, dir / "bad_cells.vtk", true).mesh);
    p.inlet.push_back(k > 0 ? plane_layer(p.slabs[k], "inlet") : PlaneLayer{});
    p.outlet.push_back(k < 2 ? plane_layer(p.slabs[k], "outlet") : PlaneLayer{});
  }
  return p;
}

PolyhedralMesh dual_of_piece(const Pieces& p, int k) {
  const SlabWithLayers s = slab_with_layers(p.slabs[k], k > 0 ? &p.outlet[k - 1] : nullptr, k < 2 ? &p.inlet[k + 1] : nullptr);
  std::vector<int> cell_points;
  const PolyhedralMesh d = dual_mesh(s.mesh, tetrahedron_centroids(s.mesh), 80.0, &cell_points);
  return dual_piece(d, cell_points, s.side, k, 3);
}

// Each cell's skewness and non-orthogonality in the dual of `mesh`, by the cell's point (the
// point's coordinates, the same bits in every piece that holds it), for the cells whose point
// has side 0 in `side` (empty: every cell).
using Figures = std::map<std::array<double, 3>, std::pair<double, double>>;
Figures figures_by_point(const PolyMesh& mesh, const std::vector<int>& side) {
  std::vector<int> cell_points;
  const PolyhedralMesh d = dual_mesh(mesh, tetrahedron_centroids(mesh), 80.0, &cell_points);
  const CellQuality q = cell_quality(d);
  Figures out;
  for (int c = 0; c < d.cells; ++c)
    if (side.empty() || side[cell_points[c]] == 0) {
      const Eigen::Vector3d& x = mesh.points[cell_points[c]];
      out[{x.x(), x.y(), x.z()}] = {q.skewness[c], q.non_orthogonality_deg[c]};
    }
  return out;
}

}  // namespace

TEST(DualPieces, EachPieceJudgesItsPolyhedraAsTheWholeDualJudgesThem) {
  // The gate of a piece's polyhedra sees, cell for cell, the skewness and non-orthogonality that
  // checkMesh sees on the whole mesh's dual: its own cells judged in the dual with its
  // neighbours' layers, whose cells' centres its faces across the planes see.
  const Pieces p = three_slabs();
  const int all = 1 << 20;
  const PlaneLayer below = plane_layer(p.slabs[0], "outlet", all), above = plane_layer(p.slabs[2], "inlet", all);
  const Figures expected = figures_by_point(slab_with_layers(p.slabs[1], &below, &above).mesh, {});
  Figures judged;
  for (int k = 0; k < 3; ++k) {
    const SlabWithLayers s =
        slab_with_layers(p.slabs[k], k > 0 ? &p.outlet[k - 1] : nullptr, k < 2 ? &p.inlet[k + 1] : nullptr);
    judged.merge(figures_by_point(s.mesh, s.side));
  }
  ASSERT_EQ(judged.size(), expected.size());
  long differ = 0;
  double worst = 0.0;
  for (const auto& [x, figures] : expected) {
    const auto it = judged.find(x);
    ASSERT_NE(it, judged.end());
    differ += std::abs(it->second.first - figures.first) > 1e-9 * (1.0 + figures.first) ||
              std::abs(it->second.second - figures.second) > 1e-9 * 90.0;
    worst = std::max(worst, figures.first);
  }
  EXPECT_EQ(differ, 0) << "of " << judged.size() << " cells";
  EXPECT_GT(worst, 0.5);  // cells whose figures a wrong neighbour would change
}

TEST(DualPieces, ThreePiecesMakeTheWholeDualWithMatchingProcessorPatches) {
  const Pieces p = three_slabs();
  // The whole mesh: the middle slab with all of the others as its layers; and its dual.
  const int all = 1 << 20;
  const PlaneLayer below = plane_layer(p.slabs[0], "outlet", all), above = plane_layer(p.slabs[2], "inlet", all);
  const SlabWithLayers whole = slab_with_layers(p.slabs[1], &below, &above);
  ASSERT_EQ(whole.mesh.cells, p.slabs[0].cells + p.slabs[1].cells + p.slabs[2].cells);
  std::vector<double> expected = cell_geometry(dual_mesh(whole.mesh, tetrahedron_centroids(whole.mesh), 80.0)).volumes;
  std::vector<PolyhedralMesh> piece;
  std::vector<double> volumes;
  for (int k = 0; k < 3; ++k) {
    piece.push_back(dual_of_piece(p, k));
    for (double v : cell_geometry(piece[k]).volumes) volumes.push_back(v);
    EXPECT_EQ(piece[k].owner.size(), piece[k].faces.size());
    EXPECT_EQ(piece[k].patches.back().type, "processor");
  }
  ASSERT_EQ(volumes.size(), expected.size());
  std::sort(volumes.begin(), volumes.end());
  std::sort(expected.begin(), expected.end());
  long differ = 0;
  for (std::size_t c = 0; c < volumes.size(); ++c) differ += std::abs(volumes[c] - expected[c]) > 1e-12 * expected.back();
  EXPECT_EQ(differ, 0) << "of " << volumes.size() << " cells";
  // The domain's own inlet and outlet are only on the end pieces; every piece lists them.
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(test_support::patch_named(piece[k], "inlet").size > 0, k == 0);
    EXPECT_EQ(test_support::patch_named(piece[k], "outlet").size > 0, k == 2);
    EXPECT_THROW(test_support::patch_named(piece[k], kLayerEdge), std::runtime_error);
  }
  const double max_non_orthogonality = QualityGate{}.max_non_orthogonality_deg;
  for (int k = 0; k < 2; ++k) {
    const PolyhedralMesh &lower = piece[k], &upper = piece[k + 1];
    const auto [a, c] = test_support::facing_patches(lower, upper, k);
    ASSERT_GT(a.size, 100);
    EXPECT_EQ(test_support::mismatched_faces(lower, a, upper, c), 0)
        << "of " << a.size << " faces between pieces " << k << " and " << k + 1;
    const CellGeometry gl = cell_geometry(lower), gu = cell_geometry(upper);
    long inverted = 0, too_oblique = 0;
    for (int f = 0; f < a.size; ++f) {
      const FaceGeometry fl = face_geometry(lower.points, lower.faces[a.start + f]);
      const Eigen::Vector3d cl = gl.centres[lower.owner[a.start + f]], cu = gu.centres[upper.owner[c.start + f]];
      inverted += (fl.centre - cl).dot(fl.area) <= 0.0;
      const FaceGeometry fu = face_geometry(upper.points, upper.faces[c.start + f]);
      inverted += (fu.centre - cu).dot(fu.area) <= 0.0;
      const double cosine = fl.area.normalized().dot((cu - cl).normalized());
      too_oblique += std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi >= max_non_orthogonality;
    }
    EXPECT_EQ(inverted, 0);
    EXPECT_EQ(too_oblique, 0);
  }
}

TEST(DualPieces, ALayerRoundTripsThroughItsFileAndAForeignOneIsRefused) {
  const Pieces p = three_slabs();
  const auto dir = test_support::fresh_dir("dual_pieces_file", true);
  PlaneLayer layer = p.outlet[0];
  layer.tag = "job 7";
  write_plane_layer(dir / "layer.bin", layer);
  const PlaneLayer back = read_plane_layer(dir / "layer.bin");
  EXPECT_EQ(back.tag, "job 7");
  EXPECT_EQ(read_plane_layer_tag(dir / "layer.bin"), "job 7");
  EXPECT_EQ(back.names, layer.names);
  EXPECT_EQ(back.points, layer.points);
  ASSERT_EQ(back.cells.size(), layer.cells.size());
  EXPECT_EQ(back.cells.back().v, layer.cells.back().v);
  EXPECT_EQ(back.patch, layer.patch);
  // Rings of tetrahedra: more than those touching the plane.
  std::vector<char> on_plane(p.slabs[0].points.size(), 0);
  for (const PolyMesh::Patch& q : p.slabs[0].patches)
    if (q.name == "outlet")
      for (int f = q.start; f < q.start + q.size; ++f)
        for (int v : p.slabs[0].faces[f]) on_plane[v] = 1;
  long touching = 0;
  for (const VolumeCell& c : tetrahedra(p.slabs[0])) touching += on_plane[c.v[0]] || on_plane[c.v[1]] || on_plane[c.v[2]] || on_plane[c.v[3]];
  EXPECT_GT(static_cast<long>(layer.cells.size()), touching);
  // Cut short: refused, naming the file.
  const auto size = std::filesystem::file_size(dir / "layer.bin");
  std::filesystem::resize_file(dir / "layer.bin", size / 2);
  EXPECT_THROW(read_plane_layer(dir / "layer.bin"), InputError);
  std::filesystem::resize_file(dir / "layer.bin", 10);
  EXPECT_THROW(read_plane_layer_tag(dir / "layer.bin"), InputError);
  // The layer of another plane (piece 2's, offered to piece 0 as its neighbour's): refused.
  EXPECT_THROW(slab_with_layers(p.slabs[0], nullptr, &p.inlet[2]), std::runtime_error);
}
