#pragma once
#include <Eigen/Core>

#include <memory>
#include <vector>

#include "core/container.hpp"

namespace bedforge {

// A packed bed: sphere centres and diameters in metres, in the frame every stage shares
// (container axis along z through the origin, floor at z = 0), and the container they fill.
struct Bed {
  std::vector<Eigen::Vector3d> centres;        // m, N
  std::vector<double> diameters;               // m, N
  std::shared_ptr<const Container> container;  // lengths in m

  std::size_t size() const { return centres.size(); }
};

}  // namespace bedforge
