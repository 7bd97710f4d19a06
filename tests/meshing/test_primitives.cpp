#include "meshing/primitives.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "meshing/surface_checks.hpp"

using namespace bedforge::meshing;

namespace {

// Signed volume by the divergence theorem (independent of CGAL).
double signed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) v += m.points[t[0]].dot(m.points[t[1]].cross(m.points[t[2]])) / 6.0;
  return v;
}

}  // namespace

TEST(Primitives, SphereIsClosedInscribedAndConverges) {
  const Eigen::Vector3d c(0.3, -0.2, 1.0);
  double previous_error = 1.0;
  for (double edge : {0.5, 0.25, 0.12, 0.06}) {
    const TriangleMesh m = sphere_mesh(c, 1.0, edge, true, "particles");
    const SurfaceCheck k = check_surface(m, 1'000'000);
    EXPECT_TRUE(k.manifold && k.closed && k.self_intersections_checked && !k.self_intersecting);
    const double exact = 4.0 / 3.0 * std::numbers::pi, error = (exact - signed_volume(m)) / exact;
    EXPECT_NEAR(k.volume, signed_volume(m), 1e-12);
    EXPECT_GT(error, 0.0);  // inscribed: every facet inside the sphere
    EXPECT_LT(error, previous_error);
    // Volume deficit of a polyhedron inside the sphere within its chordal deviation delta: at
    // most the shell 4 pi r^2 delta.
    EXPECT_LT(error * exact, 4.0 * std::numbers::pi * sphere_chordal_deviation(1.0, edge));
    previous_error = error;
    for (const auto& p : m.points) EXPECT_NEAR((p - c).norm(), 1.0, 1e-12);
    EXPECT_GT(mesh_quality(m).min_angle_deg, 45.0);
    EXPECT_LE(mesh_quality(m).max_edge, edge * 1.2);
  }
  // Inward orientation encloses a negative volume.
  EXPECT_LT(signed_volume(sphere_mesh(c, 1.0, 0.3, false, "p")), 0.0);
}

TEST(Primitives, TubeAndCapsWeldIntoAClosedCylinder) {
  // A cylinder and an annular prism from tube and ring meshes sharing their seams exactly.
  for (double r_in : {0.0, 0.7}) {
    for (double height : {1.0, 1.37}) {  // an even and an odd number of rings
      const double R = 2.0, edge = 0.21;
      TriangleMesh m;
      m.append(tube_mesh(R, 0.0, height, edge, true, "wall"));
      const bool st = top_ring_staggered(0.0, height, edge);
      m.append(ring_mesh(r_in, R, 0.0, edge, false, false, false, "inlet"));
      m.append(ring_mesh(r_in, R, height, edge, true, st, st, "outlet"));
      if (r_in > 0) m.append(tube_mesh(r_in, 0.0, height, edge, false, "inner_wall"));
      m.weld();
      const SurfaceCheck k = check_surface(m, 1'000'000);
      ASSERT_TRUE(k.manifold && k.closed) << "r_in " << r_in << " h " << height;
      EXPECT_FALSE(k.self_intersecting);
      // Inscribed polygons: volume within the sagitta of the exact prism.
      const double exact = std::numbers::pi * (R * R - r_in * r_in) * height;
      EXPECT_NEAR(k.volume, exact, 0.01 * exact);
      EXPECT_GT(mesh_quality(m).min_angle_deg, 25.0);
    }
  }
}
