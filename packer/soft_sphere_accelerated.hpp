#pragma once
#include <nlohmann/json.hpp>

#include "packer/contact_forces.hpp"
#include "packer/run_log.hpp"
#include "packer/soft_sphere.hpp"

namespace bedforge::packer {

// Accelerated mode: the force model, step and stopping tests of the published schedule, with
// two changes that remove its two slow parts.
//  1. Momentum. Eq. (4) is gradient descent; here it is Nesterov's accelerated gradient with
//     adaptive restart (O'Donoghue & Candes, Found. Comput. Math. 15, 715, 2015): momentum is
//     dropped whenever it points uphill, so stiff contacts stay as stable as in plain descent
//     while the slow collective motion (the bed creeping down at C_g d per iteration) speeds up
//     by about the square root of the stiffness-to-gravity ratio. Momentum methods are stable
//     for steps up to 1 / L where plain descent allows 2 / L (L the largest contact stiffness
//     eigenvalue), so the step is C_k / 2, and never more than 0.8 / lambda_max as measured on
//     the current contacts by power iteration every 1000 iterations: a C_k beyond the limit is
//     reduced, not obeyed. Each sphere's step is capped at delta_U / 2 so the collapse stays
//     quasi-static.
//  2. Direct control of gravity. Instead of ramping C_g by Delta C_g per iteration (Eq. 7), the
//     stiffness ratio kappa = C_k / C_g is set so the settled bed's largest pair overlap falls
//     in the band [delta_L, delta_U] (overlap ~ 1 / kappa at equilibrium), and the final stage
//     raises it in one step to bring both overlaps below half the tolerance.
// Stages: expansion (no gravity, until both overlaps < tolerance); compaction (until the
// mass-centre test passes or the rms net force falls below `force_tolerance` of the weight,
// then the band check); final (the same settling test, then overlaps < tolerance, stiffening
// again if not). The faithful schedule ends with an rms net force of 0.1-0.25 weights
// (docs/validation.md), so the default force_tolerance = 0.2 asks as much balance of the
// accelerated bed. What is left is spread through the bed and largest on spheres held by few
// contacts (1e4 spheres, a = 14: rms 0.41 weights with one contact, 0.22 with four; 0.20 in
// the bulk, 0.10-0.11 within 2 d of the floor and in the top 5 d). Divergence (non-finite
// values) returns to the last good window with a halved step, as in the faithful mode.
// A periodic section (`period` > 0, packing units; the container's axial period is then the
// longer one the spheres were generated in) has no floor and no gravity: one stage, compression,
// parts the spheres and shortens the period in steps of 0.2 % down to `period`, parting them
// again after each; where they jam first it lets the period out by 1 % and taps them (up to
// max_recoveries times), and a ConvergenceError says where they jammed last.
// Input: s with x from the generation stage. Output: s.x packed (the container's period is
// `period`); returns {"stiffness_ratio", "smallest_C_k"} (the smallest C_k the stability limit
// allowed).
nlohmann::json run_accelerated(Spheres& s, Container& container, double period, const SoftSphereSettings& p,
                               RunLog& log);

}  // namespace bedforge::packer
