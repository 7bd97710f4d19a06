#pragma once
// A small random packing for the meshing tests: `count` equal spheres of d = 1 m in a tube of
// diameter `aspect_ratio` d, packed by the soft-sphere packer (same seed, same bed).
#include "core/bed.hpp"
#include "core/progress.hpp"
#include "packer/soft_sphere.hpp"

namespace test_support {

inline bedforge::Bed packed_bed(int count, double aspect_ratio, unsigned seed) {
  bedforge::SizeDistribution spheres;
  spheres.diameters_m = {1.0};
  spheres.number_fractions = {1.0};
  bedforge::Progress quiet("pack", false);
  return bedforge::packer::pack_soft_sphere({}, spheres, bedforge::Cylinder(0.5 * aspect_ratio), count, seed, quiet)
      .bed;
}

}  // namespace test_support
