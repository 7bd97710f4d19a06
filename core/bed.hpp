#pragma once
#include <Eigen/Core>

#include <algorithm>
#include <memory>
#include <numbers>
#include <vector>

#include "core/container.hpp"

namespace bedforge {

// A packed bed: sphere centres and diameters in metres, in the frame every stage shares
// (container axis along z through the origin, floor at z = 0), and the container they fill.
struct Bed {
  std::vector<Eigen::Vector3d> centres;        // m, N
  std::vector<double> diameters;               // m, N
  std::shared_ptr<const Container> container;  // lengths in m
  // The unit of the scene's _d lengths (m) where the bed's own spheres cannot give it: an empty
  // bed (the container alone, a run whose flow has an exact answer) keeps the scene's particle
  // diameter; a window of a larger bed (a slab's spheres, a periodic section repeated) that
  // bed's, so that its lengths are the whole bed's. 0: the Sauter mean of its spheres.
  double reference_diameter_m = 0.0;

  std::size_t size() const { return centres.size(); }
};

// Sauter mean diameter sum d^3 / sum d^2 of a set of spheres (the bed's reference diameter).
inline double sauter_mean(const std::vector<double>& diameters) {
  double s3 = 0.0, s2 = 0.0;
  for (double d : diameters) s3 += d * d * d, s2 += d * d;
  return s2 > 0.0 ? s3 / s2 : 0.0;
}

// The bed's reference diameter (m): the one it keeps (Bed::reference_diameter_m), else the
// Sauter mean of its spheres.
inline double reference_diameter(const Bed& bed) {
  return bed.reference_diameter_m > 0.0 || bed.size() == 0 ? bed.reference_diameter_m : sauter_mean(bed.diameters);
}

// The largest sphere's diameter (m); an empty bed's reference diameter.
inline double largest_diameter(const Bed& bed) {
  return bed.size() > 0 ? *std::max_element(bed.diameters.begin(), bed.diameters.end()) : bed.reference_diameter_m;
}

// The spheres' total volume (m^3).
inline double solid_volume(const Bed& bed) {
  double v = 0.0;
  for (double d : bed.diameters) v += std::numbers::pi / 6.0 * d * d * d;
  return v;
}

// Height of the bed: the top of its highest sphere (m), 0 for an empty bed; along a periodic
// axis, one period.
inline double bed_height(const Bed& bed) {
  if (bed.container && bed.container->axial_period() > 0.0) return bed.container->axial_period();
  double h = 0.0;
  for (std::size_t i = 0; i < bed.size(); ++i) h = std::max(h, bed.centres[i].z() + 0.5 * bed.diameters[i]);
  return h;
}

}  // namespace bedforge
