#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "core/bed.hpp"

namespace bedforge::packer {

// What every packer returns.
struct PackResult {
  Bed bed;              // metres
  nlohmann::json info;  // the packer's report: parameters, effort, time, accuracy, history
  std::string summary;  // one line: the algorithm, its effort and accuracy
};

}  // namespace bedforge::packer
