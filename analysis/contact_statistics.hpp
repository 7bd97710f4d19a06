#pragma once
#include <vector>

#include "core/bed.hpp"

namespace bedforge::analysis {

// Contacts of a bed, for any bed (packed here or imported). Two spheres, or a sphere and a
// wall, are in contact when the gap between their surfaces is at most `gap_tolerance` (m);
// overlapping pairs have negative gaps and always count.
struct ContactStatistics {
  std::vector<int> sphere_contacts;  // per sphere: contacts with other spheres
  std::vector<int> wall_contacts;    // per sphere: contacts with the lateral walls
  std::vector<char> floor_contact;   // per sphere: 1 when touching the floor (never along a periodic axis)
  double max_pair_overlap = 0;       // m
  double max_wall_overlap = 0;       // m
  double max_floor_penetration = 0;  // m (centre closer to the floor than its radius)
  // Net force on each sphere relative to its weight when contact forces are linear in the
  // overlap with the stiffness that best balances the bed (least squares), the floor carrying
  // what presses on it. A measure of static balance that needs no knowledge of how the bed
  // was made. 0 along a periodic axis (no floor, packed without gravity: nothing to balance).
  double residual_rms = 0, residual_max = 0;
};

ContactStatistics contact_statistics(const Bed& bed, double gap_tolerance);

// A rattler carries no load: fewer than 4 contacts with spheres, walls and floor together.
inline bool is_rattler(const ContactStatistics& cs, std::size_t i) {
  return cs.sphere_contacts[i] + cs.wall_contacts[i] + cs.floor_contact[i] < 4;
}

// Spheres whose centres lie between heights z_lo and z_hi (m), walls included: how many, the
// mean of their sphere contacts (rattlers counted, as DEM studies of whole cross-sections
// quote it) and how many of them are rattlers.
struct SlabCoordination {
  long spheres = 0;
  double mean_sphere_contacts = 0;
  long rattlers = 0;
};
SlabCoordination slab_coordination(const Bed& bed, const ContactStatistics& cs, double z_lo, double z_hi);

}  // namespace bedforge::analysis
