// Processor patches: slabs of a bed, meshed each on its own (gmsh's tetrahedra), order their
// shared plane's faces alike without seeing each other: face k on one side is face k on the
// other, the same points (bit for bit) from the same 0th point, in reverse order, as
// decomposePar writes a neighbour's copy. Every piece lists the same patches first.
#include "meshing/volume/processor_patches.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "meshing/volume/slab_mesh.hpp"
#include "support/packed_bed.hpp"
#include "support/processor_faces.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::meshing;
namespace fs = std::filesystem;

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

// What each piece records of its processor faces, and the comparison the run makes of the two
// sides of a plane before OpenFOAM reads them: two pieces meshed on their own match; a face moved
// by more than OpenFOAM's match tolerance (1e-4 of the face's size, coupledPolyPatch), two faces
// swapped, a face turned over or a face missing are named, the faces written to a table.
TEST(ProcessorPatches, TheSidesOfAPlaneAreComparedAsOpenFoamComparesThemAndMismatchesNamed) {
  const Bed b = test_support::packed_bed(60, 4.0, 2);
  SurfaceParams sp;  // shrink
  sp.edge_length_d = 0.25;
  const auto dir = test_support::fresh_dir("processor_faces", true);
  // The lower two of three pieces (the planes of three pass the gate on this bed at this edge).
  std::vector<std::vector<ProcessorFaces>> sides;
  for (int k = 0; k < 2; ++k) {
    PolyMesh piece = mesh_slab(b, sp, slab_planes_d(b, sp, 3), k, 1.0, VolumeMeshParams(), dir / "bad.vtk", true).mesh;
    make_processor_patches(piece, k, 3);
    sides.push_back(processor_faces(piece));
    ASSERT_EQ(sides.back().size(), k + 1u);
    for (int j = 0; j <= k; ++j) {
      EXPECT_EQ(sides.back()[j].processor, k);
      EXPECT_EQ(sides.back()[j].neighbour, k == 0 ? 1 : j == 0 ? 0 : 2);
    }
  }
  const ProcessorFaces &lower = sides[0][0], &upper = sides[1][0];
  ASSERT_GT(lower.centres.size(), 20u);
  // Each face's size is at least the distance of its centre from its farthest point: positive.
  EXPECT_GT(*std::min_element(lower.sizes.begin(), lower.sizes.end()), 0.0);
  EXPECT_EQ(compare_processor_faces(lower, upper).what, "");
  EXPECT_EQ(compare_processor_faces(upper, lower).what, "");

  // Written and read back bit for bit; a file cut short is refused naming it.
  write_processor_faces(dir / "faces.bin", sides[1]);
  const std::vector<ProcessorFaces> back = read_processor_faces(dir / "faces.bin");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].neighbour, 2);
  EXPECT_EQ(back[1].centres, sides[1][1].centres);
  EXPECT_EQ(back[0].processor, 1);
  EXPECT_EQ(back[0].neighbour, 0);
  EXPECT_EQ(back[0].centres, upper.centres);
  EXPECT_EQ(back[0].areas, upper.areas);
  EXPECT_EQ(back[0].sizes, upper.sizes);
  fs::resize_file(dir / "faces.bin", fs::file_size(dir / "faces.bin") - 8);
  try {
    read_processor_faces(dir / "faces.bin");
    ADD_FAILURE() << "a file cut short was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("faces.bin"), std::string::npos) << e.what();
  }

  // Face 7's copy moved across the tolerance: half of it passes, twice of it is named.
  const Eigen::Vector3d along = Eigen::Vector3d(1, 2, 2) / 3.0;
  ProcessorFaces moved = upper;
  moved.centres[7] += 0.5e-4 * upper.sizes[7] * along;
  EXPECT_EQ(compare_processor_faces(lower, moved).what, "");
  moved.centres[7] = upper.centres[7] + 2e-4 * upper.sizes[7] * along;
  ProcessorMismatch m = compare_processor_faces(lower, moved);
  EXPECT_EQ(m.faces, std::vector<int>{7});
  EXPECT_NE(m.what.find("1 of procBoundary0to1's"), std::string::npos) << m.what;
  EXPECT_NE(m.what.find("first: face 7 at"), std::string::npos) << m.what;
  // Two faces swapped on one side: both named, as OpenFOAM would pair them wrong.
  ProcessorFaces swapped = upper;
  std::swap(swapped.centres[3], swapped.centres[11]);
  std::swap(swapped.areas[3], swapped.areas[11]);
  std::swap(swapped.sizes[3], swapped.sizes[11]);
  EXPECT_EQ(compare_processor_faces(lower, swapped).faces, (std::vector<int>{3, 11}));
  // A face whose copy points the same way (into the other piece too).
  ProcessorFaces turned = upper;
  turned.areas[5] = -turned.areas[5];
  m = compare_processor_faces(lower, turned);
  EXPECT_EQ(m.faces, std::vector<int>{5});
  EXPECT_NE(m.what.find("not opposed"), std::string::npos) << m.what;
  // One face fewer on the other side: the counts named.
  ProcessorFaces fewer = upper;
  fewer.centres.pop_back(), fewer.areas.pop_back(), fewer.sizes.pop_back();
  m = compare_processor_faces(lower, fewer);
  EXPECT_NE(m.what.find(fmt::format("procBoundary0to1 has {} faces, procBoundary1to0 {}", lower.centres.size(),
                                    lower.centres.size() - 1)),
            std::string::npos)
      << m.what;
  EXPECT_TRUE(m.faces.empty()) << "the faces both sides have still match";

  // The table of the swapped faces: a header and one row per face, with both sides' centres.
  write_processor_mismatch(dir / "mismatch.csv", lower, swapped, compare_processor_faces(lower, swapped));
  std::ifstream in(dir / "mismatch.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], "face,x,y,z,x_copy,y_copy,z_copy,area_m2,area_copy_m2,size_m");
  EXPECT_EQ(rows[1].substr(0, 2), "3,");
  EXPECT_EQ(rows[2].substr(0, 3), "11,");
  EXPECT_NE(rows[1].find(fmt::format("{:.12g}", swapped.centres[3].x())), std::string::npos) << rows[1];
}
