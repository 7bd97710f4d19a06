#pragma once
#include <nlohmann/json.hpp>

#include "core/bed.hpp"
#include "pipeline/console.hpp"
#include "pipeline/scene.hpp"

namespace bedforge::pipeline {

// The bed of a scene and its report entry.
struct PackStage {
  Bed bed;                // m
  nlohmann::json report;  // stages.pack: the packer's effort and accuracy, void fractions, "summary"
};

// Packs the scene's spheres (soft-sphere or Monte Carlo), or takes its imported bed after
// checking that every centre lies inside the container and above the floor (InputError naming
// the sphere otherwise; overlaps are measured and reported, not refused).
PackStage pack_stage(const Scene& scene, const Console& console);

}  // namespace bedforge::pipeline
