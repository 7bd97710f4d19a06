// A bed meshed in slabs: the slabs' cells join into one conforming mesh that fills exactly the
// slabs' surfaces, with no boundary left on the planes between them, and reads back from its
// .msh file.
#include "meshing/volume/slab_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "meshing/volume/gmsh_model.hpp"
#include "meshing/surface/surface_checks.hpp"
#include "support/packed_bed.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::meshing;
namespace fs = std::filesystem;

TEST(SlabMesh, SlabsJoinIntoOneConformingMeshFillingTheirSurfaces) {
  Progress quiet("mesh", false);
  const Bed b = test_support::packed_bed(80, 4.0, 1);
  SurfaceParams sp;  // shrink
  sp.edge_length_d = 0.15;
  VolumeMeshParams p;
  const fs::path dir = test_support::fresh_dir("slabs", true);
  const VolumeMesh vm = build_slabbed_volume_mesh(b, sp, 3, 1.0, p, dir / "fluid.msh", dir / "bad_cells.vtk", quiet);
  EXPECT_TRUE(vm.quality.bad_cells(p.gate, 1.0).empty());
  ASSERT_EQ(vm.report["slabs"].size(), 3u);

  // Each slab's surface, built again, encloses what its cells fill; together, the joined mesh.
  double enclosed = 0.0;
  long cells = 0;
  for (const auto& slab : vm.report["slabs"]) {
    SurfaceParams q = sp;
    q.clip = true;
    q.clip_bottom_d = slab["heights_d"][0].get<double>();
    q.clip_top_d = slab["heights_d"][1].get<double>();
    enclosed += check_surface(build_fluid_surface(b, q).fluid, SelfIntersectionTest::skip).volume;
    cells += slab["cells"].get<long>();
  }
  EXPECT_EQ(vm.mesh.cells, cells);
  EXPECT_NEAR(vm.quality.total_volume, enclosed, 1e-9 * enclosed);

  // No boundary face is left on a plane between slabs (where the clip planes went, each a little
  // off its asked height to keep clear of the spheres' tops and bottoms).
  for (std::size_t k = 0; k + 1 < vm.report["slabs"].size(); ++k) {
    const double h = vm.report["slabs"][k]["planes_d"][1].get<double>();
    EXPECT_EQ(h, vm.report["slabs"][k + 1]["planes_d"][0].get<double>());
    for (const auto& patch : vm.mesh.patches)
      for (int f = patch.start; f < patch.start + patch.size; ++f) {
        bool on_plane = true;
        for (int v : vm.mesh.faces[f]) on_plane = on_plane && std::abs(vm.mesh.points[v].z() - h) < 1e-9;
        EXPECT_FALSE(on_plane) << patch.name << " face on the plane at " << h << " d";
      }
  }
  // The inlet and outlet are the whole domain's, one plane each.
  for (const auto& patch : vm.mesh.patches)
    if (patch.name == "inlet" || patch.name == "outlet") {
      const double z = patch.name == "inlet" ? -sp.inlet_length_d : bed_height(b) + sp.outlet_length_d;
      for (int f = patch.start; f < patch.start + patch.size; ++f)
        for (int v : vm.mesh.faces[f]) ASSERT_NEAR(vm.mesh.points[v].z(), z, 1e-9) << patch.name;
    }
  // The .msh file (written by bedforge, not gmsh) reads back through gmsh as the same mesh.
  const PolyMesh back = read_msh(dir / "fluid.msh");
  EXPECT_EQ(back.cells, vm.mesh.cells);
  EXPECT_EQ(back.internal_faces(), vm.mesh.internal_faces());
  ASSERT_EQ(back.patches.size(), vm.mesh.patches.size());
  for (std::size_t k = 0; k < back.patches.size(); ++k) {
    EXPECT_EQ(back.patches[k].name, vm.mesh.patches[k].name);
    EXPECT_EQ(back.patches[k].size, vm.mesh.patches[k].size);
  }
}
