#pragma once
#include <nlohmann/json.hpp>

#include "core/bed.hpp"

namespace bedforge::packer {

// What every packer returns.
struct PackResult {
  Bed bed;              // metres
  nlohmann::json info;  // the packer's report: parameters, effort, time, accuracy, history
};

}  // namespace bedforge::packer
