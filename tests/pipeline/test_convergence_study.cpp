// The lengths of a convergence study's coarser levels.
#include "pipeline/convergence_study.hpp"

#include <gtest/gtest.h>

#include "meshing/surface/fluid_surface.hpp"

using namespace bedforge;
using namespace bedforge::pipeline;

// Celik et al.'s procedure needs meshes refined alike everywhere: every edge the surface rules
// ask for, the edge across narrow gaps included, and the prism layers' thickness are `scale`
// times the finest level's. Checked on
// the gap rule itself (meshing::gap_spacing, as the surface stage applies it, lengths in d)
// at points facing gaps from under the finest edge to past the coarsest.
TEST(ConvergenceStudy, ACoarserLevelScalesEveryLengthTheSurfaceAsksFor) {
  const std::string text = "[container]\ndiameter_d = 5\n[particles]\ncount = 2\ndiameter_m = 0.003\n"
                           "[surface]\nedge_length_d = 0.15\ncontact_edge_length_d = 0.05\n"
                           "cells_per_gap = 3\n[mesh.layers]\ncount = 3\nthickness_d = 0.05\n";
  const Scene scene = read_scene(toml::parse(text + "[case]\nrun = true\n"), "test");
  EXPECT_EQ(read_scene(toml::parse(text), "test").mesh.layers.room_scale, 1.0);  // no study: the rule at its own lengths
  const double scale = 1.62;
  const LevelLengths level = level_lengths(scene, scale);
  EXPECT_DOUBLE_EQ(level.surface.edge_length_d, scale * scene.surface.edge_length_d);
  EXPECT_DOUBLE_EQ(level.surface.contact_edge_length_d, scale * scene.surface.contact_edge_length_d);
  EXPECT_DOUBLE_EQ(level.mesh.max_size_d, scale * scene.mesh.max_size_d);
  // Prism layers as many, each `scale` times as thick (until 2026-11-27 they kept their
  // thickness, so a layered study refined only along the walls).
  EXPECT_DOUBLE_EQ(level.mesh.layers.thickness_d, scale * 0.05);
  EXPECT_EQ(level.mesh.layers.count, 3);
  // Their room rule at one set of lengths on every level, the coarsest's (layers_for_study): the
  // same region layered on each (before 2026-12-07 each level dropped the stacks its own
  // thickness found no room for, so the coarser levels layered less of the bed).
  EXPECT_GT(scene.mesh.layers.room_scale, 1.0);
  EXPECT_DOUBLE_EQ(level.mesh.layers.room_scale * level.mesh.layers.thickness_d,
                   scene.mesh.layers.room_scale * scene.mesh.layers.thickness_d);

  // Two spheres of diameter 1 whose surfaces are `gap` apart along x, in a wide tube; the edge
  // asked for on the first, facing the second.
  auto edge_facing = [](const meshing::SurfaceParams& p, double gap) {
    const std::vector<Eigen::Vector3d> centres{{-0.5, 0.0, 0.0}, {0.5 + gap, 0.0, 0.0}};
    const std::vector<double> radii{0.5, 0.5};
    const std::vector<char> kept{1, 1};
    const Cylinder tube{20.0};
    return meshing::gap_spacing(p, 1.0, centres, radii, kept, tube)->at({0.0, 0.0, 0.0}, 0);
  };
  int between_bounds = 0;
  for (double gap : {0.05, 0.1, 0.2, 0.3, 0.4, 0.6, 1.0}) {
    const double finest = edge_facing(scene.surface, gap);
    EXPECT_NEAR(edge_facing(level.surface, gap), scale * finest, 1e-12) << "gap " << gap << " d";
    between_bounds += finest > scene.surface.contact_edge_length_d && finest < scene.surface.edge_length_d;
  }
  EXPECT_GE(between_bounds, 2) << "no gap between the edge's bounds; the test tests nothing";
}
