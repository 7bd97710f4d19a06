#pragma once
#include <nlohmann/json.hpp>

#include <vector>

#include "core/random.hpp"
#include "core/scene_section.hpp"

namespace bedforge {

// Particle size distribution of a scene's [particles] section.
//
// The reference diameter d (the unit of every length given "in diameters") is the Sauter mean
// d32 = E[D^3] / E[D^2] of the distribution, the diameter packed-bed correlations use; for
// equal spheres it is just the diameter. Tolerances on overlaps are relative to the smallest
// possible diameter `smallest()`, so they stay meaningful for the small spheres of a mixture.
struct SizeDistribution {
  enum class Kind { monodisperse, discrete, normal, lognormal };
  Kind kind = Kind::monodisperse;
  std::vector<double> diameters_m;       // monodisperse: one; discrete: one per species
  std::vector<double> number_fractions;  // discrete: per species, summing to 1
  double mean_m = 0, std_m = 0;          // continuous: mean and standard deviation of the diameter
  double min_m = 0, max_m = 0;           // continuous: cut-offs (truncation)

  double sauter_mean() const;  // m
  double smallest() const;     // m
  double largest() const;      // m
  double mean_volume() const;  // m^3, expected sphere volume
  // `count` diameters (m). Discrete mixtures get exact counts (largest-remainder rounding) in a
  // random order; continuous ones are drawn from the truncated distribution.
  std::vector<double> sample(long long count, Rng& rng) const;
  nlohmann::json to_json() const;
  const char* kind_name() const;
};

// Reads `distribution`, `diameter_m`, `diameters_m`, `number_fractions` | `volume_fractions`,
// `mean_m`, `std_m`, `min_m`, `max_m` from [particles].
SizeDistribution read_size_distribution(SceneSection& particles);

}  // namespace bedforge
