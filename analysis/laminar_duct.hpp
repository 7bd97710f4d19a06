#pragma once
#include "core/container.hpp"

namespace bedforge::analysis {

// Fully developed laminar flow through an empty container (no spheres), the case's known
// answer: the pressure gradient dp/L (Pa/m) that drives mean velocity `velocity` (m/s) through
// its cross-section with no slip on every side (the case makes a box's four sides walls, periodic
// or not), in a fluid of dynamic viscosity `viscosity` (Pa s); container lengths in m.
//   cylinder of radius R:        8 mu u / R^2                               (Hagen-Poiseuille)
//   annulus R > r:               8 mu u / (R^2 + r^2 - (R^2 - r^2) / ln(R / r))
//   box 2b x 2c, c <= b:         3 mu u / (c^2 S),  S = 1 - 192 c / (pi^5 b) sum_{i odd} tanh(i pi b / (2 c)) / i^5
// (White, Viscous Fluid Flow, 3rd ed., 2006, section 3-3). The box's series is summed
// until its terms fall below 1e-16 of the sum, so each value is exact to rounding.
double laminar_duct_gradient(const Container& container, double viscosity, double velocity);

}  // namespace bedforge::analysis
