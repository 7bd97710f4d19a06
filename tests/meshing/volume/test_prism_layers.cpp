// Prism layers on particle surfaces: a free sphere gets full stacks whose volume is the shell
// between the sphere and its offset, stacks thin in a narrow gap so the tops never meet, and
// stacks collapse (pyramids, tetrahedra) where a particle meets a wall.
#include "meshing/volume/prism_layers.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "core/error.hpp"
#include "meshing/surface/fluid_surface.hpp"
#include "meshing/surface/surface_checks.hpp"

using namespace bedforge;
using namespace bedforge::meshing;

namespace {

FluidSurface surface_of(const Bed& b, SurfaceParams::Treatment treatment = SurfaceParams::Treatment::shrink,
                        double edge_length_d = 0.15, bool facets_hold_sphere_volume = true) {
  SurfaceParams p;
  p.facets_hold_sphere_volume = facets_hold_sphere_volume;
  p.edge_length_d = edge_length_d;
  p.contact_edge_length_d = 0.05;
  p.treatment = treatment;
  p.wall_treatment = treatment;
  return build_fluid_surface(b, p);
}

Bed bed_of(double tube_diameter, const std::vector<Eigen::Vector3d>& centres) {
  Bed b;
  b.container = std::make_shared<Cylinder>(0.5 * tube_diameter);
  for (const auto& c : centres) b.centres.push_back(c), b.diameters.push_back(1.0);
  return b;
}

PrismLayerParams three_layers(double thickness_d) {
  PrismLayerParams p;
  p.count = 3;
  p.thickness_d = thickness_d;
  return p;
}

}  // namespace

TEST(PrismLayers, AFreeSphereGetsFullStacksFillingTheShellAroundIt) {
  const Bed b = bed_of(3.0, {{0.0, 0.0, 1.0}});
  // The sphere's vertices on it (inscribed facets), for which the layers' volume below is exact.
  const FluidSurface s = surface_of(b, SurfaceParams::Treatment::shrink, 0.15, false);
  const double h = 0.05;
  const PrismLayers layers = build_prism_layers(s.fluid, 1.0, three_layers(h));
  // Nothing in front of the sphere within 0.05 / 0.2 d: every stack is whole, every cell a prism.
  EXPECT_EQ(layers.report["stacks"], layers.report["particle_vertices"]);
  EXPECT_EQ(layers.report["stacks_at_full_thickness"], layers.report["stacks"]);
  EXPECT_EQ(layers.report["cells"]["pyramids"], 0);
  EXPECT_EQ(layers.report["cells"]["tetrahedra"], 0);
  const long particle_triangles = std::count(s.fluid.patch.begin(), s.fluid.patch.end(),
                                             static_cast<int>(std::find(s.fluid.patches.begin(), s.fluid.patches.end(),
                                                                        "particles") - s.fluid.patches.begin()));
  EXPECT_EQ(static_cast<long>(layers.cells.size()), 3 * particle_triangles);
  EXPECT_EQ(static_cast<long>(layers.particle_faces.size()), particle_triangles);
  // The layers take the volume between the faceted sphere (radius r, inscribed) and its offset:
  // the fluid the tetrahedra see shrinks by V_facets(r) ((1 + h / r)^3 - 1), to the offset
  // normals' deviation from radial.
  const double before = check_surface(s.fluid, SelfIntersectionTest::skip).volume, after = check_surface(layers.top, SelfIntersectionTest::skip).volume;
  const double r = 0.5 * b.diameters[0] * SurfaceParams{}.shrink_factor;
  const double facets = check_surface(s.bed, SelfIntersectionTest::skip).volume;  // inside the faceted sphere
  EXPECT_NEAR((before - after) / (facets * (std::pow(1.0 + h / r, 3) - 1.0)), 1.0, 0.01)
      << "faceted sphere " << facets << " m^3 against " << 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_TRUE(self_intersecting_triangles(layers.top).empty());
}

TEST(PrismLayers, StacksThinBeforeAGapAndGoWhereItIsNarrow) {
  // Two spheres side by side, 0.03 d apart once shrunk: the stacks facing the gap take at most
  // 0.2 of the way across, and none is left where that would be under half the target.
  const Bed b = bed_of(3.0, {{-0.51, 0.0, 1.0}, {0.51, 0.0, 1.0}});
  const FluidSurface s = surface_of(b, SurfaceParams::Treatment::shrink, 0.05);
  const PrismLayerParams p = three_layers(0.05);
  const PrismLayers layers = build_prism_layers(s.fluid, 1.0, p);
  EXPECT_LT(layers.report["stacks"].get<long>(), layers.report["particle_vertices"].get<long>());
  EXPECT_LT(layers.report["stacks_at_full_thickness"].get<long>(), layers.report["stacks"].get<long>());
  EXPECT_GT(layers.report["cells"]["pyramids"].get<long>() + layers.report["cells"]["tetrahedra"].get<long>(), 0);
  EXPECT_TRUE(self_intersecting_triangles(layers.top).empty());
  // Across the gap, the tops of the two spheres stay at least 1 - 2 x 0.2 of the distance
  // their feet were apart.
  auto closest = [&](const std::vector<Eigen::Vector3d>& x) {
    double d = 1.0;
    for (std::size_t a = 0; a < x.size(); ++a)
      if (s.fluid.points[a].x() < -0.3 && std::abs(s.fluid.points[a].y()) < 0.3 && std::abs(s.fluid.points[a].z() - 1.0) < 0.3)
        for (std::size_t c = 0; c < x.size(); ++c)
          if (s.fluid.points[c].x() > 0.3 && std::abs(s.fluid.points[c].y()) < 0.3 && std::abs(s.fluid.points[c].z() - 1.0) < 0.3)
            d = std::min(d, (x[a] - x[c]).norm());
    return d;
  };
  EXPECT_GE(closest(layers.top.points), (1.0 - 2.0 * p.gap_fraction) * closest(s.fluid.points));
}

TEST(PrismLayers, AStudysLevelsLayerTheSameVerticesWithTheirRoomRuleAtOneScale) {
  // Two levels of a study on the gap of the test above, their lengths 0.6 apart: the finer, its
  // room rule at the coarser's lengths (room_scale 1 / 0.6), stacks the same vertices, none under
  // 0.6 of the coarser's stack (its stacks start at 0.6 of the coarser's and taper at the same
  // slope). At its own lengths (room_scale 1) it stacks more, in the narrow gap the coarser left
  // bare. One surface serves both, so the rule's local-edge term is kept out of play: at 0.1 d
  // the gap fraction binds first on both.
  const Bed b = bed_of(3.0, {{-0.51, 0.0, 1.0}, {0.51, 0.0, 1.0}});
  const FluidSurface s = surface_of(b, SurfaceParams::Treatment::shrink, 0.05);
  const double thickness = 0.1, scale = 0.6;
  PrismLayerParams finer = three_layers(thickness * scale);
  const PrismLayers own = build_prism_layers(s.fluid, 1.0, finer);
  finer.room_scale = 1.0 / scale;
  const PrismLayers coarser = build_prism_layers(s.fluid, 1.0, three_layers(thickness)),
                    same = build_prism_layers(s.fluid, 1.0, finer);
  ASSERT_EQ(coarser.report["stacks_halved"], 0);  // the rule alone decides: no check thinned a stack
  ASSERT_EQ(same.report["stacks_halved"], 0);
  auto height = [&](const PrismLayers& l, std::size_t v) { return (l.top.points[v] - s.fluid.points[v]).norm(); };
  long stacked = 0;
  for (std::size_t v = 0; v < s.fluid.points.size(); ++v) {
    const double c = height(coarser, v), f = height(same, v);
    EXPECT_EQ(c > 0.0, f > 0.0) << "vertex " << v << ": coarser " << c << ", finer " << f;
    EXPECT_GE(f, scale * c * (1.0 - 1e-12)) << "vertex " << v;
    stacked += c > 0.0;
  }
  EXPECT_EQ(stacked, coarser.report["stacks"].get<long>());
  EXPECT_LT(stacked, coarser.report["particle_vertices"].get<long>());  // the gap is in play
  EXPECT_GT(own.report["stacks"].get<long>(), stacked);
}

TEST(PrismLayers, StacksCollapseWhereAParticleMeetsTheWall) {
  // A sphere bridged to the wall: the bridge's foot on the wall belongs to both patches, so the
  // stacks there have no height and the cells beside them are pyramids and tetrahedra.
  const Bed b = bed_of(3.0, {{1.0, 0.0, 1.0}});
  const FluidSurface s = surface_of(b, SurfaceParams::Treatment::bridge, 0.1);
  const PrismLayers layers = build_prism_layers(s.fluid, 1.0, three_layers(0.02));
  EXPECT_LT(layers.report["stacks"].get<long>(), layers.report["particle_vertices"].get<long>());
  EXPECT_GT(layers.report["cells"]["pyramids"].get<long>() + layers.report["cells"]["tetrahedra"].get<long>(), 0);
  EXPECT_GT(layers.report["cells"]["prisms"].get<long>(), 0);
  EXPECT_TRUE(self_intersecting_triangles(layers.top).empty());
}

TEST(PrismLayers, SceneValuesOutsideTheirRangesAreRefusedByName) {
  for (const auto& [key, value] : std::vector<std::pair<std::string, double>>{
           {"count", -1}, {"count", 21}, {"thickness_d", 0.0}, {"growth", 0.9}, {"gap_fraction", 0.5}}) {
    toml::table t;
    if (key == "count")
      t.insert(key, static_cast<long long>(value));
    else
      t.insert(key, value);
    SceneSection section(&t, "mesh.layers");
    try {
      read_prism_layer_params(section);
      ADD_FAILURE() << key << " = " << value << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("mesh.layers." + key), std::string::npos) << e.what();
    }
  }
}
