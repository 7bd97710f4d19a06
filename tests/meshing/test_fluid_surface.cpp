// The fluid-domain surface of small beds: valid, accurate, and clear errors when a treatment
// cannot open the contacts.
#include "meshing/fluid_surface.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "core/error.hpp"
#include "meshing/stl_io.hpp"
#include "meshing/surface_checks.hpp"

using namespace bedforge;
using namespace bedforge::meshing;


TEST(FluidSurface, ShrinkOpensTouchingContactsInACylinder) {
  // A column of three touching spheres on the axis of a tube of a = 3, the bottom one on the
  // floor, and a fourth tangent to the wall and touching the middle one.
  Bed b;
  b.container = std::make_shared<Cylinder>(1.5);
  for (int k = 0; k < 3; ++k) b.centres.emplace_back(0.0, 0.0, 0.5 + k), b.diameters.push_back(1.0);
  b.centres.emplace_back(0.0, 1.0, 1.5), b.diameters.push_back(1.0);
  SurfaceParams p;
  const FluidSurface fs = build_fluid_surface(b, p);
  const SurfaceCheck k = check_surface(fs.fluid, 10'000'000);
  EXPECT_TRUE(k.manifold && k.closed && k.self_intersections_checked && !k.self_intersecting);
  EXPECT_EQ(fs.report["contacts_treated"]["particle_particle"].get<long>(), 3);
  EXPECT_EQ(fs.report["contacts_treated"]["particle_wall"].get<long>(), 1);
  // Gaps the shrink leaves: 0.01 d between touching spheres, 0.005 d at the wall.
  EXPECT_NEAR(fs.report["smallest_gap_d"]["particle_particle"].get<double>(), 0.01, 1e-9);
  EXPECT_NEAR(fs.report["smallest_gap_d"]["particle_wall"].get<double>(), 0.005, 1e-9);
  EXPECT_NEAR(fs.report["solid_volume_change_relative"].get<double>(), std::pow(0.99, 3) - 1.0, 1e-12);
  // Mesh volume against the exact fluid volume: within the discretisation (chordal deviation
  // on every sphere, sagitta on the wall) and positive (normals out of the fluid).
  const double exact = fs.report["fluid_volume_exact_m3"].get<double>();
  EXPECT_NEAR(exact, std::numbers::pi * 2.25 * (3.0 + 2.0) - 4 * 4.0 / 3.0 * std::numbers::pi * std::pow(0.495, 3), 1e-9);
  EXPECT_NEAR(k.volume, exact, 0.01 * exact);
  // The bed solid is closed too, with outward normals.
  const SurfaceCheck kb = check_surface(fs.bed, 10'000'000);
  EXPECT_TRUE(kb.closed && !kb.self_intersecting);
  EXPECT_GT(kb.volume, 0.0);
}

TEST(FluidSurface, AnnulusHasAnInnerWallPatch) {
  Bed b;
  b.container = std::make_shared<Annulus>(2.5, 1.0);
  for (int k = 0; k < 6; ++k) {
    const double t = k * std::numbers::pi / 3;
    b.centres.emplace_back(1.75 * std::cos(t), 1.75 * std::sin(t), 0.5 + 0.3 * k);
    b.diameters.push_back(1.0);
  }
  const FluidSurface fs = build_fluid_surface(b, {});
  const SurfaceCheck k = check_surface(fs.fluid, 10'000'000);
  EXPECT_TRUE(k.closed && !k.self_intersecting);
  EXPECT_NE(std::find(fs.fluid.patches.begin(), fs.fluid.patches.end(), "inner_wall"), fs.fluid.patches.end());
  const double exact = fs.report["fluid_volume_exact_m3"].get<double>();
  EXPECT_NEAR(k.volume, exact, 0.01 * exact);
}

TEST(FluidSurface, OverlapsTheTreatmentCannotOpenNameTheParticles) {
  // An imported bed with 5 % overlap: shrinking by 1 % leaves them overlapping.
  Bed b;
  b.container = std::make_shared<Cylinder>(2.0);
  b.centres = {{0, 0, 0.5}, {0.95, 0, 0.5}};
  b.diameters = {1.0, 1.0};
  try {
    build_fluid_surface(b, {});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spheres 0 and 1"), std::string::npos) << e.what();
  }
  SurfaceParams p;
  p.shrink_factor = 0.9;  // opens them
  EXPECT_NO_THROW(build_fluid_surface(b, p));
  p.treatment = SurfaceParams::Treatment::none;  // touching spheres cannot be meshed as they are
  b.centres[1].x() = 1.0;
  EXPECT_THROW(build_fluid_surface(b, p), InputError);
}

TEST(StlIo, NamedSolidsAndBinarySizes) {
  Bed b;
  b.container = std::make_shared<Cylinder>(1.0);
  b.centres = {{0, 0, 0.5}};
  b.diameters = {1.0};
  const FluidSurface fs = build_fluid_surface(b, {});
  const std::string ascii = stl_ascii_by_patch(fs.fluid);
  for (const char* patch : {"inlet", "outlet", "wall", "particles"}) {
    EXPECT_NE(ascii.find(std::string("solid ") + patch + "\n"), std::string::npos) << patch;
    EXPECT_NE(ascii.find(std::string("endsolid ") + patch + "\n"), std::string::npos) << patch;
  }
  std::size_t facets = 0;
  for (std::size_t at = 0; (at = ascii.find("facet normal", at)) != std::string::npos; ++at) ++facets;
  EXPECT_EQ(facets, fs.fluid.triangles.size());
  // Binary: 80-byte header, count, 50 bytes per triangle.
  EXPECT_EQ(stl_binary(fs.fluid, -1, "x").size(), 84 + 50 * fs.fluid.triangles.size());
}
