// The empty containers' exact laminar pressure gradients against the tabulated friction factors
// of Shah & London (1978), Laminar Flow Forced Convection in Ducts (Academic Press): Fanning
// f Re on the hydraulic diameter D_h = 4 A / P, so dp/L = 2 (f Re) mu u / D_h^2. Their tables
// give four to five digits; the tolerances are half a unit of the last one.
#include "analysis/laminar_duct.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace bedforge;
using bedforge::analysis::laminar_duct_gradient;

namespace {

const double kMu = 1.0e-3, kU = 0.01;

// Fanning f Re of a container from its gradient, on its hydraulic diameter.
double f_re(const Container& c) {
  const double dh = 4.0 * c.cross_section_area() / c.wall_perimeter();
  return laminar_duct_gradient(c, kMu, kU) * dh * dh / (2.0 * kMu * kU);
}

}  // namespace

TEST(LaminarDuct, TheTubeIsHagenPoiseuille) {
  // f Re = 16 on the diameter: dp/L = 32 mu u / D^2.
  EXPECT_NEAR(f_re(Cylinder(0.004)), 16.0, 1e-12);
  EXPECT_NEAR(laminar_duct_gradient(Cylinder(0.003), kMu, kU), 32.0 * kMu * kU / (0.006 * 0.006), 1e-9);
}

TEST(LaminarDuct, RectangularDuctsMatchShahAndLondon) {
  // Sides ratio alpha* = short / long: 1 -> 14.227, 0.5 -> 15.548, 0.25 -> 18.233, 0.125 -> 20.585.
  EXPECT_NEAR(f_re(Box(0.01, 0.01, false, false)), 14.227, 5e-4);
  EXPECT_NEAR(f_re(Box(0.02, 0.01, false, false)), 15.548, 5e-4);
  EXPECT_NEAR(f_re(Box(0.01, 0.04, false, false)), 18.233, 5e-4);
  EXPECT_NEAR(f_re(Box(0.08, 0.01, false, false)), 20.585, 5e-4);
  // The case makes a periodic box's sides walls too: the same flow.
  EXPECT_EQ(laminar_duct_gradient(Box(0.02, 0.01, true, true), kMu, kU),
            laminar_duct_gradient(Box(0.02, 0.01, false, false), kMu, kU));
}

TEST(LaminarDuct, ConcentricAnnuliMatchShahAndLondon) {
  // Radius ratio r* = inner / outer: 0.5 -> 23.81 (D_h = 2 (R - r)); the narrow-gap limit is the
  // parallel plates' 24.
  EXPECT_NEAR(f_re(Annulus(0.01, 0.005)), 23.81, 5e-3);
  EXPECT_NEAR(f_re(Annulus(0.01, 0.00999)), 24.0, 1e-3);
}
