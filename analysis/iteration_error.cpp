#include "analysis/iteration_error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bedforge::analysis {

nlohmann::json IterationError::to_json() const {
  return {{"geometric", geometric},
          {"ratio", ratio},
          {"last_change", last_change},
          {"remaining", geometric ? nlohmann::json(remaining) : nlohmann::json()},
          {"block_iterations", block}};
}

IterationError IterationError::from_json(const nlohmann::json& j) {
  IterationError e;
  e.geometric = j.at("geometric").get<bool>();
  e.ratio = j.at("ratio").get<double>();
  e.last_change = j.at("last_change").get<double>();
  e.remaining = e.geometric ? j.at("remaining").get<double>() : 0.0;
  e.block = j.at("block_iterations").get<std::size_t>();
  return e;
}

IterationError iteration_error(const std::vector<double>& values) {
  const std::size_t n = values.size();
  if (n < 3) throw std::invalid_argument(fmt::format("iteration_error: {} values, at least 3 needed", n));
  const double last = values.back();
  if (!std::isfinite(last) || last == 0.0)
    throw std::invalid_argument(fmt::format("iteration_error: the last value is {}, a finite non-zero one needed", last));
  IterationError e;
  const std::size_t m = std::min(std::max(kMinimumBlock, (n - 1) / 10), (n - 1) / 2);
  e.block = m;
  const double later = values[n - 1] - values[n - 1 - m], earlier = values[n - 1 - m] - values[n - 1 - 2 * m];
  e.last_change = later / std::abs(last);
  if (std::abs(later) <= kIterationResolution * std::abs(last) && std::abs(earlier) <= kIterationResolution * std::abs(last)) {
    e.geometric = true;  // settled to round-off: nothing left to estimate
    return e;
  }
  if (earlier == 0.0) return e;  // a change out of none: not shrinking
  e.ratio = later / earlier;
  e.geometric = e.ratio > 0.0 && e.ratio < 1.0;
  if (e.geometric) e.remaining = e.last_change * e.ratio / (1.0 - e.ratio);
  return e;
}

bool settled_within(const IterationError& e, double tolerance) {
  return std::abs(e.geometric ? e.remaining : e.last_change) <= tolerance;
}

}  // namespace bedforge::analysis
