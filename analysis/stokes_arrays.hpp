#pragma once
#include <optional>

#include "core/bed.hpp"

namespace bedforge::analysis {

// Stokes flow through a simple cubic array of spheres, the known answer for flow around spheres:
// Zick & Homsy (1982, J. Fluid Mech. 115, 13-26, Table 2, simple cubic) give the drag on each
// sphere, F = 6 pi mu a K U (a the radius, U the superficial velocity), to about 0.1 %, at the
// solid fractions phi they tabulate. Returns K at a tabulated phi (within 1e-4 of it,
// relatively), else none: no interpolation, whose error would be the reference's.
std::optional<double> zick_homsy_simple_cubic(double solid_fraction);

// The pressure gradient (Pa/m) that drives superficial velocity `velocity` (m/s) along a column
// of equal spheres that stands for a simple cubic array: a box of square section L x L whose
// sides the flow slips along (mirror planes of the array), one sphere at the centre of each
// L-long cell along the axis, z from L / 2 up, spaced L. The gradient over whole cells is the
// array's, n F = 6 pi mu a K U / L^3, with K from zick_homsy_simple_cubic. None when the bed is
// not such a column (within 1e-6 L; it may be periodic along z, the sides may not), its solid
// fraction is not tabulated, or the section
// [z_low, z_high] (m) does not span whole cells at the same phase. Stokes flow only: the caller
// checks the Reynolds number. `viscosity` dynamic, Pa s.
std::optional<double> simple_cubic_column_gradient(const Bed& bed, double viscosity, double velocity, double z_low,
                                                   double z_high);

// The same array whole: a box periodic on every side, a cube of side m L, holding m^3 equal spheres
// on a cubic lattice of spacing L (at any offset, within 1e-6 L). Its gradient is n F =
// 6 pi mu a K U / L^3, K from zick_homsy_simple_cubic; none when the bed is not such an array or
// its solid fraction is not tabulated. Stokes flow only, as above.
std::optional<double> simple_cubic_array_gradient(const Bed& bed, double viscosity, double velocity);

}  // namespace bedforge::analysis
