#pragma once
#include <vector>

#include "core/bed.hpp"

namespace bedforge::analysis {

// Axial segregation of a bed with a few distinct sphere sizes (species = distinct diameters).
struct Segregation {
  std::vector<double> diameters;                    // per species (m), largest first
  std::vector<double> z;                            // layer centres (m)
  std::vector<std::vector<double>> volume_fraction; // [species][layer]: solid volume of the species / layer volume
  // Danckwerts' (1952) intensity of segregation over the layers: the solid-volume-weighted
  // variance of the largest species' share of the solids, c_k, about its bed-wide share c:
  // I = sum_k V_k (c_k - c)^2 / (sum_k V_k c (1 - c)). 0 for a perfect mix, 1 when every layer
  // holds one species only; layers one largest diameter high keep the sampling floor low.
  double intensity = 0.0;
  // Mass-centre height of each species (m), largest first.
  std::vector<double> mean_height;
};

// Species of the bed when it has 2 to `max_species` distinct diameters (relative tolerance
// 1e-9); empty otherwise. Layers of height `layer` (m) from the floor to `top` (m), solid
// volumes from exact sphere-slab intersections.
Segregation axial_segregation(const Bed& bed, double layer, double top, std::size_t max_species = 8);

}  // namespace bedforge::analysis
