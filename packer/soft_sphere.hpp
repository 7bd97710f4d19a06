#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>

#include "core/bed.hpp"
#include "core/progress.hpp"
#include "core/scene_section.hpp"
#include "core/size_distribution.hpp"
#include "packer/pack_result.hpp"

namespace bedforge::packer {

// Soft-sphere packer of Salvat et al. (2005), scene section [packing.soft_sphere].
// Lengths are in smallest particle diameters (suffix _d); `resolve` turns them into packing
// units (reference diameters) in one place.
struct SoftSphereParams {
  enum class Mode { accelerated, faithful };
  Mode mode = Mode::accelerated;
  double initial_void_fraction = 0.47;       // eps_0 of Eq. (6)
  double stiffness_step = 0.3;               // C_k of Eq. (4), faithful mode
  double gravity_step_increment = 1.25e-7;   // Delta C_g of Eq. (7)
  double overlap_band_lower_d = 0.5e-2;      // delta_L of Eq. (7)
  double overlap_band_upper_d = 1.0e-2;      // delta_U of Eq. (7)
  double overlap_tolerance_d = 1e-4;         // end of the initial and final stages
  long mass_centre_interval = 100;           // iterations between mass-centre samples
  int mass_centre_samples = 10;              // successive samples that must agree
  double mass_centre_tolerance = 1e-6;       // relative spread allowed among them (1e-4 %)
  double force_tolerance = 0.2;              // accelerated: rms net force / own weight that ends a stage
  double final_momentum_bound = 100;         // accelerated: cap on Nesterov's t in the final stage at the default
                                             // tolerance, scaled by 1e-4 d / tolerance below it (0: none)
  long max_iterations = 5'000'000;           // all stages together
  int max_recoveries = 8;                    // step halvings allowed after detected divergence; taps of a periodic section
  double neighbour_skin_d = 0.2;             // Verlet skin
  // A periodic section's void fraction (0: unset): its period is then set from the spheres drawn,
  // total volume / ((1 - target) x cross-section), and they are compressed to it.
  double target_void_fraction = 0.0;
};

// Reads [packing.soft_sphere]; unknown keys and out-of-range values are InputErrors.
SoftSphereParams read_soft_sphere_params(SceneSection& section);
nlohmann::json to_json(const SoftSphereParams& p);

// The same settings in packing units (lengths in reference diameters d_ref).
struct SoftSphereSettings {
  SoftSphereParams given;
  double band_lower, band_upper, tolerance, skin, d_min;
};
SoftSphereSettings resolve(const SoftSphereParams& p, double d_ref_m, double d_min_m);

// Packs `count` spheres drawn from `sizes` into `container` (metres) with `seed`.
// Throws ConvergenceError when the tolerances cannot be reached within the iteration cap or
// the recoveries allowed; never returns a bed that violates them.
PackResult pack_soft_sphere(const SoftSphereParams& params, const SizeDistribution& sizes, const Container& container,
                            long long count, std::uint64_t seed, Progress& progress);

}  // namespace bedforge::packer
