#pragma once
#include <nlohmann/json.hpp>
#include <cstddef>
#include <vector>

namespace bedforge::analysis {

// The iteration error still in the last value of a quantity followed over a steady solver's
// iterations, from how its last changes shrink (Ferziger & Peric, Computational Methods for Fluid
// Dynamics, 3rd ed. 2002, sec. 5.7): late in the iterations the error decays by the iteration
// matrix's largest eigenvalue lambda < 1 per iteration, so the change over a block of m
// iterations shrinks by q = lambda^m from one block to the next, and the change still to come
// after the last value sums to the last block's times q / (1 - q).
struct IterationError {
  // The last two blocks' changes shrank geometrically: of one sign and the later smaller
  // (0 < q < 1), or both within kIterationResolution of the value. Only then is `remaining` an
  // estimate.
  bool geometric = false;
  double ratio = 0.0;        // q: the last block's change over the block's before it (0 if that was none)
  double last_change = 0.0;  // the last block's change, relative to the last value
  double remaining = 0.0;    // (settled - last) / last, estimated (0 unless geometric)
  std::size_t block = 0;     // m, the iterations in a block
  nlohmann::json to_json() const;
  static IterationError from_json(const nlohmann::json& j);
};

// Changes of a value within this fraction of it are taken as settled: the cases write their
// monitors with 10 significant digits, so such a change is a few units of the last one.
inline constexpr double kIterationResolution = 1e-9;

// A block holds at least this many iterations: on beds SIMPLE's dp/L alternates a large and a
// small step from one iteration to the next, and blocks of 4 (a tenth of a 40-iteration solve)
// swung the estimate by up to 0.3 % of dp/L between neighbouring iterations where blocks of 10
// moved it by at most 0.02 % (seven solves of the README's bed; docs/findings.md, 2026-12-07,
// session 97).
inline constexpr std::size_t kMinimumBlock = 10;

// `values`: the quantity at each iteration, the last one last; a block is a tenth of the
// iterations, at least kMinimumBlock and at most half of them (so a block of one on three
// values). std::invalid_argument with fewer than three values, or with a last value that is
// zero or not finite.
IterationError iteration_error(const std::vector<double>& values);

// Whether the quantity is settled to `tolerance` (a fraction of its value): its estimated
// remaining change is within it, or, without an estimate (its changes did not shrink), its last
// block's change is.
bool settled_within(const IterationError& e, double tolerance);

}  // namespace bedforge::analysis
