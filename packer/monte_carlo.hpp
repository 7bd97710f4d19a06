#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "core/container.hpp"
#include "core/progress.hpp"
#include "core/scene_section.hpp"
#include "core/size_distribution.hpp"
#include "packer/pack_result.hpp"

namespace bedforge::packer {

// Monte Carlo packer of Abreu et al. (1999), scene section [packing.monte_carlo]. Lengths in
// smallest particle diameters (suffix _d) unless said otherwise. The schedule (docs/monte_carlo.md):
//  (a) random placement below a lid, then `mixing_cycles` without gravity;
//  (b) `shakes` shakes under gravity: the whole bed is lifted by `shake_amplitude_d` (the floor
//      drops away, as in Rosato et al. 1987, which Castier et al. 1998 follow), optionally also
//      stretched so its top rises by `shake_dilation` x the amplitude more (every gap opens in
//      proportion to its height, as in a bed's flight phase), and settles until its mass centre
//      falls by less than `settle_tolerance_d` over `settle_block_cycles`;
//  (c) `settling_cycles` more cycles with gravity. A cycle is one trial move per particle.
struct MonteCarloParams {
  double temperature = 0.01;                       // kT / (m*_ref g d_ref): barometric height in d
  std::vector<double> particle_density = {1000.0};  // kg/m^3: one value (particle_density), or one per
                                                   // species of particles.diameters (particle_densities)
  double fluid_density = 1.0;                      // kg/m^3
  double initial_void_fraction = 0.88;             // of the volume below the lid during mixing
  std::optional<double> mixing_height_d;           // lid height in reference diameters (overrides the above)
  long mixing_cycles = 10'000;
  std::optional<long> shakes;                      // unset: the paper's 10 for equal spheres, 100 for mixtures
  double shake_amplitude_d = 1.5;
  double shake_dilation = 0.0;                     // 0: a rigid lift
  long settle_block_cycles = 100;
  double settle_tolerance_d = 1e-3;
  long max_settle_cycles = 20'000;                 // per shake; reported when reached
  long settling_cycles = 100'000;
  double target_acceptance = 0.05;                 // the maximum displacement adapts to hold it
  double max_displacement_d = 0.5;
};

MonteCarloParams read_monte_carlo_params(SceneSection& section);
nlohmann::json to_json(const MonteCarloParams& p);

// Packs `count` spheres drawn from `sizes` into `container` (metres) with `seed`. InputError
// when the input is impossible (densities, a lid too low to place the spheres); the returned
// bed has no overlap at all (checked) and lies inside the container.
PackResult pack_monte_carlo(const MonteCarloParams& params, const SizeDistribution& sizes, const Container& container,
                            long long count, std::uint64_t seed, Progress& progress);

}  // namespace bedforge::packer
