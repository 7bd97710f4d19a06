#include "analysis/pressure_drop.hpp"

#include <gtest/gtest.h>

namespace bedforge::analysis {
namespace {

// f_p = F (1 - eps) / eps^3 at eps = 0.40: the check values of ../shared/reference/correlations.md
// (section 3), given there to four significant figures.
double f_p(double f, double eps) { return f * (1.0 - eps) / (eps * eps * eps); }

TEST(PressureDrop, EisfeldSchnitzleinMatchesThePublishedCheckValues) {
  const double eps = 0.40;
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(1.0, eps, 5.0), eps), 1308.0, 0.5);
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(10.0, eps, 5.0), eps), 143.1, 0.05);
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(100.0, eps, 5.0), eps), 26.60, 0.005);
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(1.0, eps, 10.0), eps), 1083.0, 0.5);
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(10.0, eps, 10.0), eps), 120.3, 0.05);
  EXPECT_NEAR(f_p(eisfeld_schnitzlein_f(100.0, eps, 10.0), eps), 24.10, 0.005);
}

TEST(PressureDrop, ErgunMatchesThePublishedCheckValues) {
  const double eps = 0.40;
  EXPECT_NEAR(f_p(ergun_f(1.0, eps), eps), 860.2, 0.05);
  EXPECT_NEAR(f_p(ergun_f(10.0, eps), eps), 100.8, 0.05);
  EXPECT_NEAR(f_p(ergun_f(100.0, eps), eps), 24.84, 0.005);
}

TEST(PressureDrop, WallCorrectionVanishesInAWideBed) {
  // a -> infinity: A_w -> 1, B_w -> 0.87^2; the viscous term becomes Carman-like 154 / Re_m.
  const double eps = 0.4, re = 0.01;
  const double f = eisfeld_schnitzlein_f(re, eps, 1e9);
  EXPECT_NEAR(f, 154.0 * (1.0 - eps) / re + 1.0 / (0.87 * 0.87), 1e-6 * f);
}

TEST(PressureDrop, WallWettedAreaShareIsTheWallsShareOfTheSurfacePerBedVolume) {
  // Per unit bed volume, a tube of diameter D = a d has 4 / D of wall and the spheres
  // 6 (1 - eps) / d of surface; nothing of A_w enters this count.
  const double d = 0.003, eps = 0.44, a = 5.0;
  const double wall = 4.0 / (a * d), particles = 6.0 * (1.0 - eps) / d;
  EXPECT_NEAR(wall_wetted_area_share(eps, a), wall / (wall + particles), 1e-12);
  EXPECT_LT(wall_wetted_area_share(eps, 1e9), 1e-8);  // a wide bed: the wall carries nothing (2 / (3 a (1 - eps)))
}

TEST(PressureDrop, GradientHasTheUnitsOfTheDefinition) {
  // dp/L = f_p rho u^2 / d: doubling the density doubles it, doubling d halves it at fixed f.
  const double g = pressure_gradient(100.0, 0.4, 1000.0, 0.01, 0.003);
  EXPECT_NEAR(g, 100.0 * 0.6 / 0.064 * 1000.0 * 1e-4 / 0.003, 1e-9 * g);
  EXPECT_NEAR(pressure_gradient(100.0, 0.4, 2000.0, 0.01, 0.003), 2.0 * g, 1e-9 * g);
  EXPECT_NEAR(pressure_gradient(100.0, 0.4, 1000.0, 0.01, 0.006), 0.5 * g, 1e-9 * g);
}

}  // namespace
}  // namespace bedforge::analysis

// van der Hoef et al.'s Stokes drag as a gradient: its first term is Carman-Kozeny's creeping-flow
// law (F = 180 / Re_m, the table in docs/reference.md), its second the dilute array's drag over the
// spheres' number density; at vanishing solid fraction each sphere carries Stokes's 3 pi mu d U.
TEST(VanDerHoef, ItsGradientIsCarmanKozenyPlusTheDiluteTerm) {
  const double mu = 1e-3, rho = 1000.0, u = 1e-5, d = 0.003, pi = std::acos(-1.0);
  for (double phi : {0.1, 0.3, 0.4, 0.6}) {
    const double eps = 1.0 - phi, re_p = rho * u * d / mu, re_m = re_p / (1.0 - eps);
    const double carman = bedforge::analysis::pressure_gradient(180.0 / re_m, eps, rho, u, d);
    const double dilute = 18.0 * mu * u * phi * eps * (1.0 + 1.5 * std::sqrt(phi)) / (d * d);
    EXPECT_NEAR(bedforge::analysis::van_der_hoef_gradient(phi, mu, u, d), carman + dilute, 1e-12 * carman) << phi;
  }
  const double phi = 1e-8, n = 6.0 * phi / (pi * d * d * d);
  EXPECT_NEAR(bedforge::analysis::van_der_hoef_gradient(phi, mu, u, d) / (n * 3.0 * pi * mu * d * u), 1.0, 1e-3);
}
