#pragma once
#include <functional>

namespace bedforge {

// Exact volumes of a sphere cut by the shapes the void-fraction profiles use. All lengths in
// one unit (any); volumes in that unit cubed.

// Sphere of radius r centred at height zc, between the planes z = z1 and z = z2 (z1 <= z2):
// closed form from spherical caps.
double sphere_slab_volume(double r, double zc, double z1, double z2);

// Area of the intersection of a disk of radius a, centred at distance s from the origin, with
// the disk of radius rho centred at the origin (circle-circle lens, closed form).
double disk_lens_area(double a, double s, double rho);

// Sphere of radius r, centre at distance s from the z axis and at height zc, inside the
// coaxial cylinder of radius rho and between z1 and z2. The integral over z of the lens area is
// split where the lens changes form (so each piece is smooth) and each piece is integrated by
// 24-point Gauss-Legendre: relative error below 1e-9 in the tests against closed forms.
double sphere_cylinder_volume(double r, double s, double zc, double rho, double z1, double z2);

// Sphere of radius r centred at (xc, ., zc), on the side x <= x_max of a plane and between z1
// and z2: the integral over z of circular-segment areas, split where the segment changes form
// and integrated like sphere_cylinder_volume; the area has a square-root kink at the splits,
// so the relative error is about 1e-7 (tested against the cap's closed form), far below the
// sampling noise of a profile. Profiles next to the flat walls of a box.
double sphere_halfspace_volume(double r, double xc, double zc, double x_max, double z1, double z2);

// A solid of revolution between the horizontal planes z = z1 and z = z2 (z1 <= z2): its axis
// passes through a point at height `origin_z` with unit direction of z component `axis_z`, and
// at distance t along it (t0 <= t <= t1) its section is a disk of radius radius(t) >= 0. The
// integral over t of that disk's area between the planes (in the disk's plane they are two
// parallel lines, so the area is a difference of circular segments, closed form), split where
// a line meets the disk's rim, each piece mapped so that its ends' square-root kinks are smooth
// and integrated by 24-point Gauss-Legendre. `radius` must be smooth on [t0, t1]: a spherical
// cap (radius sqrt(r^2 - t^2) from its base at t0 to the pole at r) or a cylinder (constant).
// Relative error below 1e-9 in the tests against closed forms (sphere_halfspace_volume, the
// comparison for caps, is good to about 1e-7).
double revolution_slab_volume(double origin_z, double axis_z, double t0, double t1,
                              const std::function<double(double)>& radius, double z1, double z2);

}  // namespace bedforge
