#pragma once
#include <nlohmann/json.hpp>

#include "packer/contact_forces.hpp"
#include "packer/run_log.hpp"
#include "packer/soft_sphere.hpp"

namespace bedforge::packer {

// The published schedule (Salvat et al. 2005, Sec. 3): Jacobi updates of Eq. (4) with fixed
// C_k; initial stage with C_g = 0 until both maximum overlaps < tolerance; intermediate stage
// with the C_g control loop of Eq. (7) (C_g clamped at >= 0) until the mass centre, sampled
// every `mass_centre_interval` iterations, stays within the relative tolerance over
// `mass_centre_samples` successive samples; final stage halving C_g after each such
// mass-centre convergence until both maximum overlaps < tolerance.
//
// Eq. (4) is gradient descent with unit step on Phi = C_k E_el + C_g sum w_i z_i, which must
// not increase while C_k stays below the stability limit. A window in which Phi rises too often,
// or any non-finite value, is treated as divergence: the run returns to the last good window and
// halves C_k (recorded as a recovery); after `max_recoveries` it stops with ConvergenceError.
//
// Input: s with x from the generation stage (packing units). Output: s.x packed; returns
// {"C_k", "C_g", "stiffness_ratio"} at the end (stiffness_ratio = C_k / C_g, contact stiffness in
// weights per reference diameter of overlap).
nlohmann::json run_faithful(Spheres& s, const Container& container, const SoftSphereSettings& p, RunLog& log);

}  // namespace bedforge::packer
