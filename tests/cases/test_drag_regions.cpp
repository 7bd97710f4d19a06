#include "cases/drag_regions.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

using namespace bedforge;
using namespace bedforge::cases;

namespace {

// Two unit spheres 1.2 apart along x in a cylinder of radius 2: a gap of 0.2 between them, and
// sphere A's far side 0.4 from the wall (its centre at x = -0.6).
Bed two_spheres() {
  Bed bed;
  bed.centres = {{-0.6, 0.0, 1.0}, {0.6, 0.0, 1.0}};
  bed.diameters = {1.0, 1.0};
  bed.container = std::make_shared<Cylinder>(2.0);
  return bed;
}

// A patch of `size` faces from `start` (no cyclic or processor fields).
meshing::PolyMesh::Patch patch(const std::string& name, const std::string& type, int start, int size) {
  meshing::PolyMesh::Patch p;
  p.name = name, p.type = type, p.start = start, p.size = size;
  return p;
}

}  // namespace

// The gap at a point on a sphere is the distance to the other sphere or to the wall, whichever is
// nearer, exactly (points on the sphere), and capped at the reach.
TEST(DragRegions, GapIsTheDistanceToTheNearestOtherSurface) {
  const Bed bed = two_spheres();
  const std::vector<Eigen::Vector3d> points = {
      {-0.1, 0.0, 1.0},  // A's point facing B: 0.2 to B's nearest point
      {-1.1, 0.0, 1.0},  // A's far side: 2 - 1.1 = 0.9 to the wall
      {-0.6, 0.0, 1.5},  // A's top: farther than the reach from B and the wall
      {0.1, 0.0, 1.0},   // B's point facing A
  };
  const std::vector<double> gaps = gaps_at_particle_points(points, bed, 0.5);
  EXPECT_NEAR(gaps[0], 0.2, 1e-12);
  EXPECT_NEAR(gaps[1], 0.5, 1e-12);  // 0.9 capped at the reach
  EXPECT_NEAR(gaps[3], 0.2, 1e-12);
  const double to_b = (Eigen::Vector3d(-0.6, 0.0, 1.5) - bed.centres[1]).norm() - 0.5;  // 0.8: beyond the reach
  EXPECT_GT(to_b, 0.5);
  EXPECT_NEAR(gaps[2], 0.5, 1e-12);
  const std::vector<double> wide = gaps_at_particle_points(points, bed, 2.0);
  EXPECT_NEAR(wide[1], 0.9, 1e-12);
  EXPECT_NEAR(wide[2], std::min(to_b, 2.0 - 0.6), 1e-12);  // B, nearer than the wall at radius 0.6
}

// Across a periodic side the nearest sphere is an image: two spheres 0.3 apart through x = +-L/2.
TEST(DragRegions, GapTakesPeriodicImages) {
  Bed bed;
  const double L = 4.0;
  bed.centres = {{-L / 2 + 0.6, 0.0, 1.0}, {L / 2 - 0.6, 0.0, 1.0}};  // 1.2 apart through the side
  bed.diameters = {1.0, 1.0};
  bed.container = std::make_shared<Box>(L, L, true, true);
  const std::vector<double> gaps = gaps_at_particle_points({{-L / 2 + 0.1, 0.0, 1.0}}, bed, 1.0);
  EXPECT_NEAR(gaps[0], 0.2, 1e-12);
}

// Splitting keeps every face with its owner, puts each particle face between the section's
// planes in its gap's band and the others in particles_ends (faces of one band in the order they
// had), and leaves the other patches' faces where they were.
TEST(DragRegions, SplitKeepsTheFacesAndBandsThem) {
  const Bed bed = two_spheres();
  meshing::PolyMesh m;
  m.cells = 4;
  // Particle faces: small triangles around points of A at known gaps (0.2 facing B, 0.9 from the
  // wall on the far side, 0.8 from B on top but above the section's top plane z = 1.4),
  // interleaved; one inlet face before, one outlet after.
  const std::vector<std::pair<Eigen::Vector3d, double>> at = {
      {{-0.1, 0.0, 1.0}, 0.2}, {{-1.1, 0.0, 1.0}, 0.9}, {{-0.6, 0.0, 1.5}, 0.8}, {{-0.1, 0.0, 1.0}, 0.2}};
  auto triangle = [&](const Eigen::Vector3d& c) {
    const int first = static_cast<int>(m.points.size());
    for (const Eigen::Vector3d& e : {Eigen::Vector3d(0, 1e-3, 0), Eigen::Vector3d(0, -1e-3, 1e-3),
                                     Eigen::Vector3d(0, -1e-3, -1e-3)})
      m.points.push_back(c + e);
    m.faces.push_back(meshing::Face{first, first + 1, first + 2});
  };
  triangle({0.0, 0.0, 0.0});
  m.owner.push_back(0);
  for (std::size_t k = 0; k < at.size(); ++k) triangle(at[k].first), m.owner.push_back(static_cast<int>(k));
  triangle({0.0, 0.0, 3.0});
  m.owner.push_back(3);
  m.patches = {patch("inlet", "patch", 0, 1), patch("particles", "wall", 1, 4), patch("outlet", "patch", 5, 1)};
  const meshing::PolyMesh before = m;

  const std::vector<GapBand> bands = split_particles_by_gap(m, bed, 1.0, {0.5, 0.85}, 0.0, 1.4);
  ASSERT_EQ(bands.size(), 4u);
  EXPECT_EQ(bands[0].faces, 2);  // the two at 0.2
  EXPECT_EQ(bands[1].faces, 0);  // 0.8, but beyond the section
  EXPECT_EQ(bands[2].faces, 1);  // 0.9
  EXPECT_EQ(bands[3].faces, 1);  // the top one
  EXPECT_FALSE(bands[3].in_section);
  EXPECT_NEAR(bands[0].area_m2, 2.0 * 2e-6, 1e-15);  // each triangle: base 2e-3, height 2e-3
  ASSERT_EQ(m.patches.size(), 6u);
  const std::vector<std::string> names = {"inlet",          "particles_gap0", "particles_gap1",
                                          "particles_gap2", "particles_ends", "outlet"};
  const std::vector<int> starts = {0, 1, 3, 3, 4, 5};
  for (std::size_t k = 0; k < names.size(); ++k) {
    EXPECT_EQ(m.patches[k].name, names[k]);
    EXPECT_EQ(m.patches[k].start, starts[k]);
  }
  EXPECT_EQ(m.patches[1].type, "wall");
  // Band by band, in the order they had: faces 1 and 4 (owners 0, 3), then 2 (owner 1), then the
  // top one, 3 (owner 2).
  const std::vector<int> from = {0, 1, 4, 2, 3, 5};
  ASSERT_EQ(m.faces.size(), from.size());
  for (std::size_t k = 0; k < from.size(); ++k) {
    EXPECT_EQ(std::vector<int>(m.faces[k].begin(), m.faces[k].end()),
              std::vector<int>(before.faces[from[k]].begin(), before.faces[from[k]].end()));
    EXPECT_EQ(m.owner[k], before.owner[from[k]]);
  }

  // The polyhedral mesh's faces are split alike.
  meshing::PolyhedralMesh p;
  p.points = before.points;
  for (const auto& f : before.faces) p.faces.push_back(std::vector<int>(f.begin(), f.end()));
  p.owner = before.owner;
  p.patches = before.patches;
  p.cells = before.cells;
  const std::vector<GapBand> same = split_particles_by_gap(p, bed, 1.0, {0.5, 0.85}, 0.0, 1.4);
  for (std::size_t k = 0; k < from.size(); ++k) {
    const auto face = p.faces[k];
    EXPECT_EQ(std::vector<int>(face.begin(), face.end()),
              std::vector<int>(before.faces[from[k]].begin(), before.faces[from[k]].end()));
  }
  EXPECT_EQ(same[2].faces, 1);

  // The bands, in a Drag, read back from its JSON as they were (a study reads its levels back).
  Drag drag;
  drag.particles_by_gap = bands;
  drag.walls_n = 1.5, drag.particles_by_gap[3].form_n = -0.25;
  const Drag back = Drag::from_json(drag.to_json());
  EXPECT_EQ(back.to_json(), drag.to_json());
  ASSERT_EQ(back.particles_by_gap.size(), bands.size());
  for (std::size_t k = 0; k < bands.size(); ++k) {
    EXPECT_EQ(back.particles_by_gap[k].number, bands[k].number);
    EXPECT_EQ(back.particles_by_gap[k].patch(), bands[k].patch());
  }

  // Without a particles patch nothing changes.
  meshing::PolyMesh empty = before;
  empty.patches = {patch("inlet", "patch", 0, 6)};
  EXPECT_TRUE(split_particles_by_gap(empty, bed, 1.0, {0.5}, 0.0, 1.4).empty());
  EXPECT_EQ(empty.patches.size(), 1u);
}

// A band's projected area and moment are OpenFOAM's face area vectors out of the fluid (into the
// solid): over a closed solid, sum S_z = 0 and sum z S_z = -its volume (Gauss), here an octahedron
// inscribed in sphere A (volume 4 a^3 / 3), all its faces in one band.
TEST(DragRegions, WallsAreSplitAtTheSectionsPlanes) {
  // Wall faces at heights 0.5, 2.0 and 1.0 and an inner wall's at 3.0, between an inlet face and
  // a particle face; the section spans z 0.8 to 1.6.
  meshing::PolyMesh m;
  m.cells = 6;
  for (double z : {0.0, 0.5, 2.0, 1.0, 3.0, 1.2}) {
    const int first = static_cast<int>(m.points.size());
    for (const Eigen::Vector3d& e :
         {Eigen::Vector3d(0, 0, 1e-3), Eigen::Vector3d(1e-3, 0, 0), Eigen::Vector3d(0, 1e-3, 0)})
      m.points.push_back(Eigen::Vector3d(0, 0, z) + e);
    m.faces.push_back(meshing::Face{first, first + 1, first + 2});
    m.owner.push_back(static_cast<int>(m.owner.size()));
  }
  m.patches = {patch("inlet", "patch", 0, 1), patch("wall", "wall", 1, 3), patch("inner_wall", "wall", 4, 1),
               patch("particles", "wall", 5, 1)};
  const meshing::PolyMesh before = m;

  EXPECT_EQ(split_walls_at_section(m, 0.8, 1.6), 3);
  const std::vector<std::string> names = {"inlet", "wall", "wall_ends", "inner_wall", "inner_wall_ends", "particles"};
  const std::vector<int> starts = {0, 1, 2, 4, 4, 5}, sizes = {1, 1, 2, 0, 1, 1};
  ASSERT_EQ(m.patches.size(), names.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    EXPECT_EQ(m.patches[k].name, names[k]);
    EXPECT_EQ(m.patches[k].start, starts[k]);
    EXPECT_EQ(m.patches[k].size, sizes[k]);
  }
  EXPECT_EQ(m.patches[2].type, "wall");
  // The face at 1.0 first, then those at 0.5 and 2.0 in their order; the rest in place.
  const std::vector<int> from = {0, 3, 1, 2, 4, 5};
  for (std::size_t k = 0; k < from.size(); ++k) EXPECT_EQ(m.owner[k], before.owner[from[k]]);
}

TEST(DragRegions, ProjectedAreaAndMomentFollowTheFacesIntoTheSolid) {
  const Bed bed = two_spheres();
  const Eigen::Vector3d c = bed.centres[0];
  const double a = 0.5;
  meshing::PolyMesh m;
  m.cells = 1;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) m.points.push_back(c + sign * a * Eigen::Vector3d::Unit(axis));
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        std::array<int, 3> t{sx, 2 + sy, 4 + sz};
        const Eigen::Vector3d n =
            (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]);
        if (n.dot(m.points[t[0]] - c) > 0.0) std::swap(t[1], t[2]);  // towards the centre: into the solid
        m.faces.push_back(meshing::Face(t));
        m.owner.push_back(0);
      }
  m.patches = {patch("particles", "wall", 0, 8)};
  const std::vector<GapBand> bands = split_particles_by_gap(m, bed, 1.0, {10.0}, -5.0, 5.0);
  ASSERT_EQ(bands.size(), 3u);
  EXPECT_EQ(bands[0].faces, 8);
  EXPECT_NEAR(bands[0].area_z_m2, 0.0, 1e-15);
  EXPECT_NEAR(bands[0].moment_z_m3, -4.0 * a * a * a / 3.0, 1e-12);
  EXPECT_NEAR(bands[0].area_m2, 8.0 * std::sqrt(3.0) / 2.0 * a * a, 1e-12);  // 8 equilateral of side a sqrt 2
}
