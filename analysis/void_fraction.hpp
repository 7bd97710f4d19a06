#pragma once
#include <vector>

#include "core/bed.hpp"
#include "core/container.hpp"

namespace bedforge::analysis {

// Void fraction of the container between heights z1 < z2 (m), from exact sphere-slab volumes.
// Overlaps between spheres (at most the packer's tolerance) are counted twice; a sphere's
// part beyond the wall (at most the same tolerance) is counted as inside.
double void_fraction(const Bed& bed, double z1, double z2);

struct Profile {
  std::vector<double> position;      // bin centre (m): distance from the wall, or height
  std::vector<double> void_fraction; // per bin
};

// Radial profile between heights z1 and z2 over coaxial shells of width `bin` (m), measured from
// a wall at radius `wall` towards radius `end` (m; inward from a cylinder wall to the axis, or
// outward from an annulus' inner wall), void fraction of each shell from exact sphere-shell
// volumes (the volume-intersection method of Abreu et al. 1999). Positions are distances from
// the wall; the last bin ends at `end`.
Profile radial_void_fraction(const Bed& bed, double wall, double end, double bin, double z1, double z2);

// Profile next to the two flat walls of a box at +-half_width along `axis` (0 = x, 1 = y),
// folded together: bins of width `bin` (m) from the walls to the mid-plane, between heights z1
// and z2, over the box's full extent `other_width` (m) along the other axis; exact volumes
// (sphere_halfspace_volume). Positions are distances from the walls.
Profile wall_void_fraction(const Bed& bed, int axis, double half_width, double other_width, double bin, double z1,
                           double z2);

// Axial profile: slabs of height `bin` (m) from the floor to `top` (m).
Profile axial_void_fraction(const Bed& bed, double bin, double top);

// Radial distribution of sphere centres with z1 <= z < z2 over bins of width `bin` (m) from the
// wall at radius `wall` towards `end` (as radial_void_fraction): the fraction of all those
// centres per bin, and their number density per unit area relative to the mean over
// `reachable_area` (m^2, the cross-section centres can reach).
struct CentreDistribution {
  std::vector<double> position;  // bin centre, distance from the wall (m)
  std::vector<double> fraction;
  std::vector<double> relative_density;
};
CentreDistribution radial_centre_distribution(const Bed& bed, double wall, double end, double bin, double z1,
                                              double z2, double reachable_area);

}  // namespace bedforge::analysis
