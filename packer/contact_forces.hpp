#pragma once
#include <Eigen/Core>

#include <numbers>
#include <vector>

#include "core/container.hpp"
#include "core/neighbour_list.hpp"

namespace bedforge::packer {

// The spheres being packed, in packing units: lengths in reference diameters d, masses in
// units of the mass of a sphere of diameter d (so weight = mass with g = 1).
struct Spheres {
  std::vector<Eigen::Vector3d> x;  // centres, N
  std::vector<double> r;           // radii, N
  std::vector<double> w;           // weights (d_i / d)^3, N
  std::size_t size() const { return x.size(); }
};

// Total volume of the spheres (length^3, packing units).
inline double total_volume(const Spheres& s) {
  double v = 0.0;
  for (double r : s.r) v += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  return v;
}

// Linear-spring contact state of a configuration, per unit stiffness (Salvat et al. 2005,
// Eqs. 2a-2b with k = 1): push[i] = sum over sphere and wall contacts of overlap * unit normal
// pushing sphere i out, so the contact force is k * push[i].
struct Contacts {
  std::vector<Eigen::Vector3d> push;  // N, length
  double max_pair_overlap = 0;        // length
  double max_wall_overlap = 0;        // length (lateral walls)
  double elastic_energy = 0;          // 1/2 sum of squared overlaps over pairs and walls, length^2
};

// Fills `out` for the spheres `s` (neighbour list `nl` up to date). Sphere pairs whose centres
// coincide are pushed apart along z, lower index downwards, so the result is always finite.
void evaluate_contacts(const Spheres& s, const NeighbourList& nl, const Container& c, Contacts& out);

// Rigid floor z = 0 (Salvat et al.: it carries exactly the axial load of the spheres resting on
// it; the packers keep z_i >= r_i). Whether sphere i rests on the floor.
inline bool on_floor(const Spheres& s, std::size_t i) { return s.x[i].z() <= s.r[i] * (1.0 + 1e-12); }

// Largest eigenvalue of the contact stiffness matrix per unit k (the Hessian of the elastic
// energy, overlap-curvature terms dropped) of the current contacts, by power iteration: the
// descent of Eq. (4) is stable for C_k below 2 / lambda, a momentum method below 1 / lambda.
// A lower estimate that converges from below; callers keep a margin.
double contact_stiffness_eigenvalue(const Spheres& s, const NeighbourList& nl, const Container& c, int iterations = 40);

// A fixed hash of (i, salt) as a number in [0, 1): perturbations that keep runs reproducible
// whatever the thread count.
double hashed_uniform(std::uint64_t i, std::uint64_t salt);

// Plain descent cannot leave an unstable equilibrium: spheres clamped to the floor share one
// height exactly, so two of them squeezed together by a narrow wall push each other only
// sideways and nothing lifts either (the net push on each is zero). Lifts every sphere resting
// on the floor by a pseudo-random height in [0, `height`) (a fixed hash of the sphere index and
// `salt`, so runs stay reproducible). Returns how many were lifted.
std::size_t lift_floor_spheres(Spheres& s, double height, std::uint64_t salt);

// Force residual of a configuration in force balance under gravity with contact stiffness
// `kappa` (in weights per unit overlap): net force on each sphere (contacts, weight, floor
// reaction) relative to its own weight; returns {rms over spheres, max}.
std::pair<double, double> force_residual(const Spheres& s, const Contacts& c, double kappa);

}  // namespace bedforge::packer
