// Which known answer or reference a case is compared with (cases/case_writer: set_known_answers).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "cases/case_writer.hpp"
#include "analysis/stokes_arrays.hpp"
#include "core/container.hpp"

using bedforge::Bed;
using bedforge::cases::CaseInfo;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Three unit (mm) spheres at no lattice's places in a cube of 4 mm periodic on every side.
Bed random_array(double third_diameter) {
  auto box = std::make_shared<bedforge::Box>(0.004, 0.004, true, true);
  box->set_axial_period(0.004);
  Bed bed;
  bed.container = box;
  bed.centres = {{-0.0012, 0.0003, 0.0007}, {0.0009, -0.0011, 0.0021}, {0.0002, 0.0014, 0.0033}};
  bed.diameters = {0.001, 0.001, third_diameter};
  return bed;
}

// What write_case knows before it sets the answers: a box periodic on every side has no walls.
CaseInfo periodic_info(const Bed& bed, double reynolds) {
  CaseInfo info;
  info.params.reynolds = reynolds;
  info.params.viscosity_pa_s = 1e-3;
  info.velocity_m_s = reynolds * 1e-6 / 0.001;
  info.particles = true;
  info.walls = false;
  double solid = 0.0;
  for (double d : bed.diameters) solid += kPi / 6.0 * d * d * d;
  info.section.void_fraction_bed = 1.0 - solid / (0.004 * 0.004 * 0.004);
  return info;
}

}  // namespace

TEST(CaseWriter, ARandomArrayIsComparedWithVanDerHoefOnlyWhenItsSpheresAreEqual) {
  // Equal spheres at Stokes flow: van der Hoef et al. at the solid fraction and size solved.
  const Bed equal = random_array(0.001);
  CaseInfo info = periodic_info(equal, 0.01);
  bedforge::cases::set_known_answers(info, equal, {1.0, 0});
  ASSERT_TRUE(info.stokes_array.has_value());
  EXPECT_NEAR(info.stokes_array->solid_fraction, 3.0 * kPi / 6.0 / 64.0, 1e-12);
  EXPECT_DOUBLE_EQ(info.stokes_array->diameter_m, 0.001);
  EXPECT_GT(info.stokes_array->pa_m, 0.0);
  EXPECT_TRUE(info.stokes_array_not_compared.empty());
  EXPECT_FALSE(info.exact_pressure_gradient_pa_m.has_value());

  // Shrunk by one scale: the spheres as solved, a solid fraction smaller by its cube.
  CaseInfo shrunk = periodic_info(equal, 0.01);
  bedforge::cases::set_known_answers(shrunk, equal, {0.98, -1});
  ASSERT_TRUE(shrunk.stokes_array.has_value());
  EXPECT_NEAR(shrunk.stokes_array->solid_fraction, 3.0 * kPi / 6.0 / 64.0 * 0.98 * 0.98 * 0.98, 1e-12);
  EXPECT_DOUBLE_EQ(shrunk.stokes_array->diameter_m, 0.00098);

  // Unequal spheres: no drag from a fit for equal ones, and the reason said.
  const Bed unequal = random_array(0.0012);
  CaseInfo mixed = periodic_info(unequal, 0.01);
  bedforge::cases::set_known_answers(mixed, unequal, {1.0, 0});
  EXPECT_FALSE(mixed.stokes_array.has_value());
  EXPECT_NE(mixed.stokes_array_not_compared.find("equal spheres"), std::string::npos) << mixed.stokes_array_not_compared;

  // Past Stokes flow (Re_p 1) neither: their drag is Stokes flow's.
  CaseInfo inertial = periodic_info(equal, 1.0);
  bedforge::cases::set_known_answers(inertial, equal, {1.0, 0});
  EXPECT_FALSE(inertial.stokes_array.has_value());
  EXPECT_TRUE(inertial.stokes_array_not_compared.empty());
}

// A simple cubic column in a slip-walled box (the array's mirror planes) at Stokes flow: exact with
// its own spheres; treated, Zick & Homsy's untreated array bounds it, from below when the treatment
// adds solid and from above when it takes it; a treatment doing both, or not known, gets neither.
TEST(CaseWriter, ATreatedSimpleCubicColumnIsBoundedByTheUntreatedArray) {
  const double d = 0.003, L = d;  // touching: solid fraction pi / 6, tabulated (K = 42.1)
  Bed column;
  column.container = std::make_shared<bedforge::Box>(L, L, false, false);
  for (int k = 0; k < 6; ++k) column.centres.emplace_back(0.0, 0.0, (k + 0.5) * L), column.diameters.push_back(d);
  auto info_for = [&] {
    CaseInfo info;
    info.params.reynolds = 0.01;
    info.params.viscosity_pa_s = 1e-3;
    info.params.slip_walls = true;
    info.velocity_m_s = 0.01 * 1e-6 / d;
    info.particles = true;
    info.section.z_low = 1.0 * L, info.section.z_high = 5.0 * L;
    return info;
  };
  const std::optional<double> untreated = bedforge::analysis::simple_cubic_column_gradient(
      column, 1e-3, 0.01 * 1e-6 / d, 1.0 * L, 5.0 * L);
  ASSERT_TRUE(untreated.has_value());

  CaseInfo kept = info_for();
  bedforge::cases::set_known_answers(kept, column, {1.0, 0});
  ASSERT_TRUE(kept.exact_pressure_gradient_pa_m.has_value());
  EXPECT_DOUBLE_EQ(*kept.exact_pressure_gradient_pa_m, *untreated);
  EXPECT_FALSE(kept.bound.has_value());

  CaseInfo bridged = info_for();
  bedforge::cases::set_known_answers(bridged, column, {0.0, 1});
  EXPECT_FALSE(bridged.exact_pressure_gradient_pa_m.has_value());
  ASSERT_TRUE(bridged.bound.has_value());
  EXPECT_DOUBLE_EQ(bridged.bound->pa_m, *untreated);
  EXPECT_TRUE(bridged.bound->from_below);
  EXPECT_TRUE(bridged.bound->holds(1.001 * *untreated));
  EXPECT_FALSE(bridged.bound->holds(0.999 * *untreated));
  EXPECT_TRUE(bridged.bound->reached_by(0.9 * *untreated, 1.001 * *untreated));  // a band
  EXPECT_FALSE(bridged.bound->reached_by(0.9 * *untreated, 0.999 * *untreated));

  CaseInfo shrunk = info_for();
  bedforge::cases::set_known_answers(shrunk, column, {0.99, -1});
  ASSERT_TRUE(shrunk.bound.has_value());
  EXPECT_FALSE(shrunk.bound->from_below);
  EXPECT_TRUE(shrunk.bound->holds(0.999 * *untreated));
  EXPECT_TRUE(shrunk.bound->reached_by(0.999 * *untreated, 1.1 * *untreated));
  EXPECT_FALSE(shrunk.bound->reached_by(1.001 * *untreated, 1.1 * *untreated));
  EXPECT_FALSE(shrunk.stokes_array.has_value());  // a lattice, not a random array

  CaseInfo both = info_for();
  bedforge::cases::set_known_answers(both, column, {0.0, 0});
  EXPECT_FALSE(both.bound.has_value());
  EXPECT_FALSE(both.exact_pressure_gradient_pa_m.has_value());
}

// The bound as report.json and study.json hold it reads back as it was; a side other than below
// or above is refused rather than read as one of them.
TEST(CaseWriter, ABoundReadsBackFromItsJson) {
  using bedforge::cases::KnownBound;
  for (const KnownBound b : {KnownBound{0.147, true}, KnownBound{2.5e3, false}}) {
    const KnownBound read = KnownBound::from_json(b.to_json());
    EXPECT_EQ(read.pa_m, b.pa_m);
    EXPECT_EQ(read.from_below, b.from_below);
  }
  EXPECT_EQ((KnownBound{1.0, false}.to_json()["side"]), "above");
  EXPECT_THROW(KnownBound::from_json({{"pa_m", 1.0}, {"side", "Below"}}), std::runtime_error);
  EXPECT_THROW(KnownBound::from_json({{"pa_m", 1.0}}), nlohmann::json::exception);
}
