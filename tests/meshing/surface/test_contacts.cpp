// treat_contacts_measured_between: the treated solid between two heights, against closed forms
// computed here another way, and against the whole the treatment measures by its own formulas.
#include "meshing/surface/contacts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/intersection_volumes.hpp"
#include "support/packed_bed.hpp"

using namespace bedforge;
using namespace bedforge::meshing;
using Treatment = SurfaceParams::Treatment;
constexpr double kPi = std::numbers::pi;

namespace {

Bed pair_of_spheres(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Bed bed;
  bed.container = std::make_shared<Cylinder>(2.0);
  bed.centres = {a, b};
  bed.diameters = {1.0, 1.0};
  return bed;
}

SurfaceParams treated(Treatment t) {
  SurfaceParams p;
  p.treatment = p.wall_treatment = t;
  return p;
}

// Area of a disk of radius R between the lines at signed distances s1 < s2 from its centre.
double disk_between(double R, double s1, double s2) {
  auto below = [R](double s) {
    s = std::clamp(s, -R, R);
    return R * R * (std::asin(s / R) + 0.5 * kPi) + s * std::sqrt(R * R - s * s);
  };
  return below(s2) - below(s1);
}

}  // namespace

// Two touching spheres side by side at z = 2, bridged: a horizontal cylinder of radius 0.1 and
// length 1 - 2 sqrt(0.24) joins their cut faces. Planes at 1.95 and 2.5 cut through it: each
// sphere's part is its slab less what lies beyond its cut plane x = +-sqrt(0.24) (the
// half-space closed form), the bridge's its length times the disk's strip.
TEST(TreatedBetween, AHorizontalBridgeCutLengthwise) {
  const Bed bed = pair_of_spheres({-0.5, 0.0, 2.0}, {0.5, 0.0, 2.0});
  const double z1 = 1.95, z2 = 2.5, r = 0.5, rho = 0.1, h = std::sqrt(r * r - rho * rho);
  const TreatedBed tb = treat_contacts_measured_between(bed, treated(Treatment::bridge), z1, z2);
  const double sphere = sphere_halfspace_volume(r, -0.5, 2.0, -0.5 + h, z1, z2);  // each, by symmetry
  const double bridge = (1.0 - 2.0 * h) * disk_between(rho, z1 - 2.0, z2 - 2.0);
  EXPECT_NEAR(tb.solid_volume_between_m3, 2.0 * sphere + bridge, 1e-7 * tb.solid_volume);
  EXPECT_NEAR(tb.untreated_volume_between_m3, 2.0 * sphere_slab_volume(r, 2.0, z1, z2), 1e-12);
}

// Two touching spheres stacked at z = 1.5 and 2.5, bridged: a vertical cylinder from
// 1.5 + sqrt(0.24) to 2.5 - sqrt(0.24). Planes at 1 and 2 take the lower sphere below its cut,
// the bridge up to 2, and nothing of the upper sphere.
TEST(TreatedBetween, AVerticalBridgeCutAcross) {
  const Bed bed = pair_of_spheres({0.0, 0.0, 1.5}, {0.0, 0.0, 2.5});
  const double r = 0.5, rho = 0.1, h = std::sqrt(r * r - rho * rho);
  const TreatedBed tb = treat_contacts_measured_between(bed, treated(Treatment::bridge), 1.0, 2.0);
  const double expected = sphere_slab_volume(r, 1.5, 1.0, 1.5 + h) + kPi * rho * rho * (2.0 - (1.5 + h));
  EXPECT_NEAR(tb.solid_volume_between_m3, expected, 1e-9 * tb.solid_volume);
}

// Capped side by side: each sphere cut flat 0.01 from the contact, so between the planes it is
// the half-space part left of x = 0.49 from its centre.
TEST(TreatedBetween, CapsCutLengthwise) {
  const Bed bed = pair_of_spheres({-0.5, 0.0, 2.0}, {0.5, 0.0, 2.0});
  const double z1 = 1.9, z2 = 2.2;
  const TreatedBed tb = treat_contacts_measured_between(bed, treated(Treatment::cap), z1, z2);
  EXPECT_NEAR(tb.solid_volume_between_m3, 2.0 * sphere_halfspace_volume(0.5, -0.5, 2.0, -0.01, z1, z2),
              1e-7 * tb.solid_volume);
}

// On a packed bed with its walls, for every treatment that adds or removes solid at contacts:
// between heights beyond the bed, the whole treated solid (which the treatment sums by its own
// formulas); and slabs through the contacts add up to it.
TEST(TreatedBetween, SlabsThroughABedAddUpToItsWholeSolid) {
  const Bed bed = test_support::packed_bed(30, 3.0, 1);
  const double top = bed_height(bed);
  for (Treatment t : {Treatment::bridge, Treatment::cap, Treatment::enlarge, Treatment::shrink}) {
    const SurfaceParams p = treated(t);
    const TreatedBed tb = treat_contacts_measured_between(bed, p, -10.0, top + 10.0);
    EXPECT_NEAR(tb.solid_volume_between_m3, tb.solid_volume, 1e-9 * tb.solid_volume) << treatment_name(t);
    double sum = 0.0;
    const std::vector<double> heights = {-10.0, 0.37, 1.0, 1.51, 2.2, 2.93, top + 10.0};
    for (std::size_t k = 0; k + 1 < heights.size(); ++k)
      sum += treat_contacts_measured_between(bed, p, heights[k], heights[k + 1]).solid_volume_between_m3;
    // The bridges to the wall are integrated with a kink where a generator meets a height:
    // about 1e-6 of their own volume (1e-3 d^3 each), so 1e-8 of the whole.
    EXPECT_NEAR(sum, tb.solid_volume, 1e-8 * tb.solid_volume) << treatment_name(t);
    EXPECT_GT(std::abs(tb.solid_volume / tb.untreated_volume_between_m3 - 1.0), 1e-5)
        << treatment_name(t) << ": the treatment changes the solid";
  }
}
