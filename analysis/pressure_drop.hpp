#pragma once
#include <cmath>

namespace bedforge::analysis {

// Pressure drop of a packed bed of spheres as the friction factor
//   f_p = (dp/L) (d / (rho u^2)) eps^3 / (1 - eps) = F(Re_m),   Re_m = Re_p / (1 - eps),
// with u the superficial velocity and Re_p = rho u d / mu.

// Eisfeld & Schnitzlein's stated accuracy, relative: particle-resolved CFD studies commonly
// compare within about +-20 % of it, and its own data scatter as much (docs/reference.md, grade C).
inline constexpr double kEisfeldSchnitzleinAccuracy = 0.20;

// Eisfeld & Schnitzlein (2001), Chem. Eng. Sci. 56:4321, spheres, with the wall correction:
//   F = K1 A_w^2 / Re_m + A_w / B_w,  K1 = 154,  A_w = 1 + 2 / (3 a (1 - eps)),
//   B_w = (k1 / a^2 + k2)^2,  k1 = 1.15,  k2 = 0.87,
// for 0.01 <= Re_p <= 17635, 1.624 <= a <= 250, 0.33 <= eps <= 0.882; a = D/d (for an annulus
// its hydraulic aspect ratio); accurate to kEisfeldSchnitzleinAccuracy.
inline double eisfeld_schnitzlein_f(double reynolds_p, double eps, double aspect_ratio) {
  const double re_m = reynolds_p / (1.0 - eps);
  const double a_w = 1.0 + 2.0 / (3.0 * aspect_ratio * (1.0 - eps));
  const double b_w = std::pow(1.15 / (aspect_ratio * aspect_ratio) + 0.87, 2);
  return 154.0 * a_w * a_w / re_m + a_w / b_w;
}

// The wall's share of a bed's wetted area, (A_w - 1) / A_w = (4 / D) / (4 / D + 6 (1 - eps) / d):
// the share of the friction that Eisfeld & Schnitzlein's A_w (Mehta & Hawley's hydraulic radius)
// gives the wall, which takes the shear as uniform over walls and particles alike.
inline double wall_wetted_area_share(double eps, double aspect_ratio) {
  const double a_w = 1.0 + 2.0 / (3.0 * aspect_ratio * (1.0 - eps));
  return (a_w - 1.0) / a_w;
}

// Stokes flow through random arrays of equal spheres (no wall), van der Hoef, Beetstra & Kuipers
// (2005, J. Fluid Mech. 528, 233), their fit to lattice-Boltzmann drag at solid fractions
// phi = 0.1-0.6: F = 10 phi / (1 - phi)^2 + (1 - phi)^2 (1 + 1.5 sqrt(phi)), the mean drag per sphere
// over Stokes's 3 pi mu d U (U superficial) without the mean pressure gradient's buoyancy-like
// share; the gradient holding the spheres is then n 3 pi mu d U F / (1 - phi), n = 6 phi / (pi d^3):
//   dp/L = 18 mu U phi F / (d^2 (1 - phi))   (Pa/m; mu Pa s, U m/s, d m).
// Its first term alone is Carman-Kozeny's 180 mu U phi^2 / (d^2 (1 - phi)^3), as the authors put it;
// the fit's accuracy against their simulations is not copied here (the paper is not at hand).
inline double van_der_hoef_f(double phi) {
  return 10.0 * phi / ((1.0 - phi) * (1.0 - phi)) + (1.0 - phi) * (1.0 - phi) * (1.0 + 1.5 * std::sqrt(phi));
}
inline double van_der_hoef_gradient(double phi, double viscosity, double velocity, double diameter) {
  return 18.0 * viscosity * velocity * phi * van_der_hoef_f(phi) / (diameter * diameter * (1.0 - phi));
}

// Ergun (1952): F = 150 / Re_m + 1.75, for a > 10 and 1 < Re_m < ~700.
inline double ergun_f(double reynolds_p, double eps) { return 150.0 * (1.0 - eps) / reynolds_p + 1.75; }

// Pressure gradient dp/L (Pa/m) from F: rho u^2 / d (1 - eps) / eps^3 F.
inline double pressure_gradient(double f, double eps, double density, double velocity, double diameter) {
  return f * (1.0 - eps) / (eps * eps * eps) * density * velocity * velocity / diameter;
}

}  // namespace bedforge::analysis
