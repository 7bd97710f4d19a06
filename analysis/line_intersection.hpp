#pragma once
#include <Eigen/Core>

#include "analysis/void_fraction.hpp"
#include "core/bed.hpp"

namespace bedforge::analysis {

// Line-intersection method of Reyes & Iglesia (1991) as used by Abreu et al. (1999), Eqs. 7-21.
// p(z, rho) is the length of the horizontal circle of radius rho around the container axis at
// height z that lies inside spheres; the local void fraction is 1 - p / (2 pi rho).

// Length (m) of the circle (radius rho > 0, height z, centred on the axis) inside the sphere
// of centre c and radius r. The sphere cuts the plane z in a disk of radius a = sqrt(r^2 -
// (z - c_z)^2) at distance s from the axis; by the law of cosines the circle enters that disk
// at the half-angle theta with cos(theta) = (rho^2 + s^2 - a^2) / (2 rho s), clamped to [-1, 1],
// which covers all six cases of the paper's Fig. 2 at once.
double circle_length_in_sphere(double rho, double z, const Eigen::Vector3d& c, double r);

// Radial profile by line intersection between heights z1 and z2: at the middle radius of each
// bin of width `bin` from the wall at radius `wall` towards `end` (as radial_void_fraction),
// eps = 1 - mean over z of p(z, rho) / (2 pi rho), the z-mean by the midpoint rule with steps
// of at most `dz` (m). Positions are distances from the wall.
Profile line_radial_void_fraction(const Bed& bed, double wall, double end, double bin, double z1, double z2, double dz);

}  // namespace bedforge::analysis
