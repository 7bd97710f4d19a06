// Processor patches: slabs of a bed, meshed each on its own (gmsh's tetrahedra), order their
// shared plane's faces alike without seeing each other: face k on one side is face k on the
// other, the same points (bit for bit) from the same 0th point, in reverse order, as
// decomposePar writes a neighbour's copy. Every piece lists the same patches first.
#include "meshing/volume/processor_patches.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "meshing/volume/slab_mesh.hpp"
#include "support/packed_bed.hpp"
#include "support/processor_faces.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::meshing;

TEST(ProcessorPatches, ThreePiecesMatchTheirSharedPlanesFaceForFace) {
  const Bed b = test_support::packed_bed(60, 4.0, 2);
  SurfaceParams sp;  // shrink
  sp.edge_length_d = 0.25;
  VolumeMeshParams p;
  const auto dir = test_support::fresh_dir("processor_patches", true);
  const int pieces = 3;
  std::vector<PolyMesh> piece;
  std::vector<long> boundary_faces;
  for (int k = 0; k < pieces; ++k) {
    piece.push_back(mesh_slab(b, sp, slab_planes_d(b, sp, pieces), k, 1.0, p, dir / "bad_cells.vtk", true).mesh);
    long faces = 0;
    for (const auto& q : piece.back().patches) faces += q.size;
    boundary_faces.push_back(faces);
    const int internal = piece.back().internal_faces();
    make_processor_patches(piece.back(), k, pieces);
    // The internal faces stay; the boundary keeps every face, owned by the same cells' count.
    EXPECT_EQ(piece.back().internal_faces(), internal);
    EXPECT_EQ(static_cast<long>(piece.back().faces.size()) - internal, faces);
    EXPECT_EQ(piece.back().owner.size(), piece.back().faces.size());
  }
  // The same patches in the same order on every piece, the processor patches after them, the
  // boundary laid out patch after patch from the last internal face.
  for (int k = 0; k < pieces; ++k) {
    const auto& patches = piece[k].patches;
    const std::vector<std::string> expected_tail =
        k == 0 ? std::vector<std::string>{"procBoundary0to1"}
        : k == 1 ? std::vector<std::string>{"procBoundary1to0", "procBoundary1to2"}
                 : std::vector<std::string>{"procBoundary2to1"};
    ASSERT_EQ(patches.size(), piece[0].patches.size() - 1 + expected_tail.size());
    int start = piece[k].internal_faces();
    for (std::size_t j = 0; j < patches.size(); ++j) {
      EXPECT_EQ(patches[j].start, start);
      start += patches[j].size;
      if (j < patches.size() - expected_tail.size()) {
        EXPECT_EQ(patches[j].name, piece[0].patches[j].name);
        EXPECT_NE(patches[j].type, "processor");
      } else {
        EXPECT_EQ(patches[j].name, expected_tail[j - (patches.size() - expected_tail.size())]);
        EXPECT_EQ(patches[j].type, "processor");
        EXPECT_EQ(patches[j].processor, k);
      }
    }
    EXPECT_EQ(start, static_cast<int>(piece[k].faces.size()));
    // The domain's own inlet and outlet are only on the end pieces.
    EXPECT_EQ(test_support::patch_named(piece[k], "inlet").size > 0, k == 0);
    EXPECT_EQ(test_support::patch_named(piece[k], "outlet").size > 0, k == pieces - 1);
  }
  // Each shared plane: face for face, point for point.
  for (int k = 0; k + 1 < pieces; ++k) {
    const PolyMesh &lower = piece[k], &upper = piece[k + 1];
    const auto [a, c] = test_support::facing_patches(lower, upper, k);
    ASSERT_GT(a.size, 50);
    EXPECT_EQ(test_support::mismatched_faces(lower, a, upper, c), 0)
        << "of " << a.size << " faces on the plane above piece " << k;
    // Flat on the plane, each normal out of its own piece.
    for (int f = 0; f < a.size; ++f) {
      EXPECT_GT(face_geometry(lower.points, lower.faces[a.start + f]).area.z(), 0.0);
      EXPECT_LT(face_geometry(upper.points, upper.faces[c.start + f]).area.z(), 0.0);
    }
  }
}

TEST(ProcessorPatches, RefusesAPieceOutsideTheCount) {
  PolyMesh m;
  EXPECT_THROW(make_processor_patches(m, 2, 2), std::runtime_error);
  EXPECT_THROW(make_processor_patches(m, 0, 2), std::runtime_error);  // no inlet patch
}
