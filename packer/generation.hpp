#pragma once
#include "core/container.hpp"
#include "core/random.hpp"
#include "packer/contact_forces.hpp"

namespace bedforge::packer {

// Generation stage of Salvat et al. (2005), Sec. 3.1, for any container and size mix: the
// initial bed height follows from the initial void fraction eps0 (Eq. 6 generalised:
// L0 = total sphere volume / (cross-section area (1 - eps0))), and each centre is drawn
// uniformly in the cross-section (container's sample_centre) and at z = L0 Rnd + r_i.
// Along a periodic axis (container.axial_period() = H > 0) eps0 is unused: z = H Rnd, one period.
// Overlaps are allowed; the packer removes them.
// Inputs: s.r (radii, packing units), container in packing units, eps0 in (0, 1).
// Output: s.x, and s reordered by height (indices follow z). Returns L0 and the reordering:
// sphere i of the output was sphere order[i] of the input.
struct Generated {
  double initial_height;
  std::vector<std::size_t> order;
};
Generated generate_initial_bed(Spheres& s, const Container& container, double eps0, Rng& rng);

// Eq. (6) generalised: the height L0 the spheres s fill in `container` at void fraction eps0.
inline double initial_height(const Spheres& s, const Container& container, double eps0) {
  return total_volume(s) / (container.cross_section_area() * (1.0 - eps0));
}

}  // namespace bedforge::packer
