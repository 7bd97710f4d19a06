// The fluid surface of a box periodic on every side: closed, each pair of opposite sides one
// triangulation point for point, the spheres cut at the sides and edges adding up to the solid.
#include "meshing/surface/periodic_box.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <set>

#include "core/error.hpp"
#include "core/random.hpp"
#include "meshing/surface/surface_checks.hpp"

using namespace bedforge;
using namespace bedforge::meshing;

namespace {

// `count` unit spheres placed at random (seeded) in a box of side `side` d periodic on every
// side, none nearer another (over periodic images) than 0.05 d: the sides, wherever the surface
// puts them, cut some spheres, and the box's edges pierce some.
Bed random_array(int count, double side, std::uint64_t seed) {
  Bed b;
  auto box = std::make_shared<Box>(side, side, true, true);
  box->set_axial_period(side);
  b.container = box;
  Rng rng(seed);
  const Periodicity per = box->periodicity();
  while (static_cast<int>(b.size()) < count) {
    const Eigen::Vector3d c(side * (rng.uniform() - 0.5), side * (rng.uniform() - 0.5), side * rng.uniform());
    bool apart = true;
    for (const auto& o : b.centres) apart = apart && per.separation(c, o).norm() > 1.05;
    if (apart) b.centres.push_back(c), b.diameters.push_back(1.0);
  }
  return b;
}

SurfaceParams plain() {
  SurfaceParams p;
  p.treatment = SurfaceParams::Treatment::none;
  p.wall_treatment = SurfaceParams::Treatment::none;
  p.edge_length_d = 0.15;
  p.contact_edge_length_d = 0.06;
  return p;
}

// The triangles of patch `name`, each as its points' two coordinates other than `axis`, from
// its smallest, turned the other way round when `flip`.
std::set<std::array<std::array<double, 2>, 3>> side(const TriangleMesh& m, const std::string& name, int axis, bool flip) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  std::set<std::array<std::array<double, 2>, 3>> out;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    if (m.patches[m.patch[k]] != name) continue;
    auto t = m.triangles[k];
    if (flip) std::swap(t[1], t[2]);
    std::array<std::array<double, 2>, 3> q;
    for (int j = 0; j < 3; ++j) q[j] = {m.points[t[j]][u], m.points[t[j]][v]};
    std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
    out.insert(q);
  }
  return out;
}

}  // namespace

// Three random arrays at solid fractions about 0.3 (25 spheres in a box of 3.5 d): the surface is
// closed, 2-manifold, free of self-intersection; the lower and upper side of each axis hold the
// same triangles (the same doubles in the two other coordinates, facing opposite ways) and lie
// exactly on their planes; its volume lies between the exact fluid volume and that plus the
// spheres' area times the chordal deviation (the facets are chords of the spheres, the sides
// exact planes).
TEST(PeriodicBox, OppositeSidesAreOneTriangulationAndTheSurfaceIsClosed) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const Bed bed = random_array(25, 3.5, seed);
    const FluidSurface s = build_periodic_box_surface(bed, plain());
    const SurfaceCheck check = check_surface(s.fluid, SelfIntersectionTest::all_pairs);
    EXPECT_TRUE(check.closed && check.manifold && !check.self_intersecting) << "seed " << seed << check.to_json().dump();
    const nlohmann::json& box = s.report["periodic_box"];
    EXPECT_GT(box["spheres_cut"].get<long>(), 0) << "seed " << seed;
    EXPECT_GT(box["edge_points"].get<long>(), 0) << "seed " << seed << ": no sphere at an edge, the test misses them";
    const std::array<std::array<const char*, 2>, 3> pairs{{{"x_min", "x_max"}, {"y_min", "y_max"}, {"inlet", "outlet"}}};
    const std::array<double, 3> upper{1.75, 1.75, 3.5};
    for (int a = 0; a < 3; ++a) {
      const auto lower = side(s.fluid, pairs[a][0], a, true), up = side(s.fluid, pairs[a][1], a, false);
      EXPECT_FALSE(lower.empty());
      EXPECT_EQ(lower, up) << "seed " << seed << ", axis " << a;
      for (std::size_t k = 0; k < s.fluid.triangles.size(); ++k) {
        if (s.fluid.patches[s.fluid.patch[k]] != pairs[a][1]) continue;
        for (int v : s.fluid.triangles[k]) EXPECT_EQ(s.fluid.points[v][a], upper[a]);
      }
    }
    const double area = 25 * std::numbers::pi, chordal = s.report["chordal_deviation_d"].get<double>();
    EXPECT_GE(check.volume, s.exact_volume_m3 * (1.0 - 1e-12)) << "seed " << seed;
    EXPECT_LE(check.volume, s.exact_volume_m3 + area * chordal) << "seed " << seed;
  }
}

// With the spheres' facets holding their volume, the box stays closed and free of
// self-intersection, its sides one triangulation each (their vertices stay: they are the loops),
// and its fluid volume is far nearer the exact one than inscribed.
TEST(PeriodicBox, SpheresHoldingTheirVolumeKeepTheSidesAndTheVolume) {
  const Bed bed = random_array(25, 3.5, 1);
  SurfaceParams p = plain();
  p.cells_per_gap = kSceneCellsPerGap;
  std::array<double, 2> error{};
  for (bool volume : {false, true}) {
    p.facets_hold_sphere_volume = volume;
    const FluidSurface s = build_periodic_box_surface(bed, p);
    const SurfaceCheck check = check_surface(s.fluid, SelfIntersectionTest::all_pairs);
    EXPECT_TRUE(check.closed && check.manifold && !check.self_intersecting) << volume;
    const std::array<std::array<const char*, 2>, 3> pairs{{{"x_min", "x_max"}, {"y_min", "y_max"}, {"inlet", "outlet"}}};
    for (int a = 0; a < 3; ++a) EXPECT_EQ(side(s.fluid, pairs[a][0], a, true), side(s.fluid, pairs[a][1], a, false)) << a;
    error[volume] = check.volume / s.exact_volume_m3 - 1.0;
    EXPECT_EQ(s.report["sphere_vertices_moved_out_d"].get<double>() > 0.0, volume);
  }
  EXPECT_GT(error[0], 0.0);  // inscribed: the spheres' facets inside them, the fluid larger
  // Measured 2026-12-06 under the scenes' gap rule: +0.57 % inscribed, +0.030 % holding their
  // volume (0.053 of it): what stays is beside the loops where the sides cut the spheres, whose
  // vertices stay on them or within an edge of the sides (match_sphere_volume); without the gap
  // rule 0.13 of it, the vertices in unresolved gaps staying too.
  EXPECT_LT(std::abs(error[1]), 0.1 * error[0]) << error[0] << " -> " << error[1];
}

// Spheres that touch across a side have no room for the fluid between them: refused with the
// treatment that parts them; a treatment that would join contacts across a side, and a box
// periodic on one side only, are refused by key.
TEST(PeriodicBox, WhatItCannotMeshIsRefusedByKey) {
  Bed touching = random_array(2, 3.5, 1);
  touching.centres = {{-1.25, 0.0, 1.0}, {1.25, 0.0, 1.0}};  // 1.0 apart across x = +-1.75
  try {
    build_periodic_box_surface(touching, plain());
    ADD_FAILURE() << "touching spheres were meshed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"shrink\""), std::string::npos) << e.what();
  }
  // The treatment's own check (the mesh estimate treats the bed before the surface) says the same
  // of spheres touching inside the box.
  Bed inside = touching;
  inside.centres = {{-0.5, 0.0, 1.0}, {0.5, 0.0, 1.0}};
  try {
    fluid_domain_profile(inside, plain(), 0.24, 1);
    ADD_FAILURE() << "touching spheres were treated";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"shrink\""), std::string::npos) << e.what();
  }
  SurfaceParams shrunk = plain();
  shrunk.treatment = shrunk.wall_treatment = SurfaceParams::Treatment::shrink;
  EXPECT_NO_THROW(build_periodic_box_surface(touching, shrunk));
  SurfaceParams bridged = plain();
  bridged.treatment = SurfaceParams::Treatment::bridge;
  EXPECT_THROW(check_periodic_box(*touching.container, bridged), InputError);
  Box one_side(3.5, 3.5, true, false);
  one_side.set_axial_period(3.5);
  EXPECT_THROW(check_periodic_box(one_side, plain()), InputError);
}
