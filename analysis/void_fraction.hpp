#pragma once
#include <vector>

#include "core/bed.hpp"
#include "core/container.hpp"

namespace bedforge::analysis {

// Height of the bed: top of its highest sphere (m).
double bed_height(const Bed& bed);

// Void fraction of the container between heights z1 < z2 (m), from exact sphere-slab volumes.
// Overlaps between spheres (at most the packer's tolerance) are counted twice; a sphere's
// part beyond the wall (at most the same tolerance) is counted as inside.
double void_fraction(const Bed& bed, double z1, double z2);

struct Profile {
  std::vector<double> position;      // bin centre (m): distance from the wall, or height
  std::vector<double> void_fraction; // per bin
};

// Radial profile of a cylinder bed between heights z1 and z2: bins of width `bin` (m) measured
// from the wall inward, void fraction of each cylindrical shell from exact sphere-shell volumes
// (the volume-intersection method of Abreu et al. 1999). The innermost bin ends at the axis.
Profile radial_void_fraction(const Bed& bed, const Cylinder& cylinder, double bin, double z1, double z2);

// Axial profile: slabs of height `bin` (m) from the floor to `top` (m).
Profile axial_void_fraction(const Bed& bed, double bin, double top);

// Radial distribution of sphere centres with z1 <= z < z2 over wall distance bins of width `bin`
// (m): the fraction of those centres per bin and their number density per unit annulus volume
// relative to the mean number density of centres in the whole annulus region they can reach.
struct CentreDistribution {
  std::vector<double> position;  // bin centre, distance from the wall (m)
  std::vector<double> fraction;
  std::vector<double> relative_density;
};
CentreDistribution radial_centre_distribution(const Bed& bed, const Cylinder& cylinder, double bin, double z1, double z2);

}  // namespace bedforge::analysis
