// The iteration error left in a monitored value (Ferziger & Peric 2002, sec. 5.7) on sequences
// whose limit is known: an exact geometric decay must give its limit back, a sum of two decays
// nearly so once the slower one dominates, and sequences that do not shrink geometrically must
// not be given an estimate.
#include "analysis/iteration_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

using namespace bedforge::analysis;

namespace {

// limit + sum of amplitude * rate^k for k = 0 .. n - 1.
std::vector<double> decay(double limit, std::vector<std::pair<double, double>> modes, int n) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) {
    double x = limit;
    for (const auto& [amplitude, rate] : modes) x += amplitude * std::pow(rate, k);
    v.push_back(x);
  }
  return v;
}

double remaining_exact(const std::vector<double>& v, double limit) { return (limit - v.back()) / v.back(); }

}  // namespace

TEST(IterationError, AGeometricDecayGivesItsLimitBack) {
  for (double rate : {0.5, 0.9, 0.98})
    for (double amplitude : {3.0, -3.0})
      for (int n : {21, 147, 340}) {
        const std::vector<double> v = decay(10.0, {{amplitude, rate}}, n);
        const IterationError e = iteration_error(v);
        ASSERT_TRUE(e.geometric) << rate << " " << amplitude << " " << n;
        EXPECT_EQ(e.block, std::min(std::max(kMinimumBlock, static_cast<std::size_t>(n - 1) / 10), static_cast<std::size_t>(n - 1) / 2));
        // The fast, long decays settle to round-off before their end, where no ratio is taken.
        if (std::abs(e.last_change) > kIterationResolution) {
          EXPECT_NEAR(e.ratio, std::pow(rate, e.block), 1e-9);
        }
        // Exact but for round-off, which limits the slowest, longest decay.
        EXPECT_NEAR(e.remaining, remaining_exact(v, 10.0), 1e-12 + 1e-6 * std::abs(remaining_exact(v, 10.0)))
            << rate << " " << amplitude << " " << n;
        EXPECT_NEAR(e.last_change, (v.back() - v[v.size() - 1 - e.block]) / v.back(), 1e-15);
      }
}

// Two modes, the faster gone by the last blocks: the estimate is the slower mode's, within the
// faster one's share of the last changes.
TEST(IterationError, TheSlowestModeDominatesLateIterations) {
  const std::vector<double> v = decay(10.0, {{3.0, 0.95}, {-20.0, 0.7}}, 200);
  const IterationError e = iteration_error(v);
  ASSERT_TRUE(e.geometric);
  EXPECT_NEAR(e.remaining / remaining_exact(v, 10.0), 1.0, 1e-6);
}

// SIMPLE's dp/L on beds alternates a large and a small step of one sign: a decay with a small
// mode of alternating sign beside its monotone one (steps of -0.049 and -0.011 times 0.9^k).
// Blocks of an even number of iterations see both modes shrink alike, so the estimate is the
// limit's at every length of a solve; blocks of an odd number (a tenth of 31-40 or 51-60
// iterations) would see the alternating mode flip sign from block to block.
TEST(IterationError, StepsAlternatingLargeAndSmallAreEstimatedAtEveryLengthOfASolve) {
  for (int n = 21; n <= 100; ++n) {
    const std::vector<double> v = decay(10.0, {{0.3, 0.9}, {0.01, -0.9}}, n);
    const IterationError e = iteration_error(v);
    ASSERT_TRUE(e.geometric) << n;
    EXPECT_NEAR(e.remaining / remaining_exact(v, 10.0), 1.0, 1e-6) << n;
  }
}

TEST(IterationError, ASettledValueLeavesNothing) {
  const IterationError e = iteration_error(std::vector<double>(50, 7.5));
  EXPECT_TRUE(e.geometric);
  EXPECT_EQ(e.remaining, 0.0);
  EXPECT_EQ(e.last_change, 0.0);
}

// Changes that do not shrink from block to block, or swing in sign, say nothing of where the
// value will settle.
TEST(IterationError, NoEstimateUnlessTheChangesShrink) {
  std::vector<double> drifting, growing, swinging;
  for (int k = 0; k < 120; ++k) {
    drifting.push_back(10.0 + 0.01 * k);
    growing.push_back(10.0 + 0.001 * std::pow(1.05, k));
    swinging.push_back(10.0 + std::pow(-0.9, k));  // a block of 11 iterations: its changes alternate in sign
  }
  for (const auto* v : {&drifting, &growing, &swinging}) {
    const IterationError e = iteration_error(*v);
    EXPECT_FALSE(e.geometric) << e.to_json().dump();
    EXPECT_EQ(e.remaining, 0.0);
    EXPECT_TRUE(e.to_json()["remaining"].is_null());
  }
}

TEST(IterationError, RefusesTooFewValuesAndAZeroLastValue) {
  EXPECT_THROW(iteration_error({1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(iteration_error({1.0, 2.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(iteration_error({1.0, 2.0, std::nan("")}), std::invalid_argument);
}

// Settled to a tolerance: by the estimate where there is one, else by the last block's change.
// Over 100 values (blocks of 10), 100 + 0.5 x 0.9^k has 1.5e-7 of its value still to come, 100 +
// 0.5 x 0.99^k 1.8e-3 (0.5 x 0.9^99 and 0.5 x 0.99^99, over 100); over 112 values (blocks of
// 11), 100 + 0.04 (-1)^k, with no estimate (its blocks' changes swing in sign), moved 0.08 over
// its last block, 8.0e-4 of its value.
TEST(IterationError, SettledWithinATolerance) {
  std::vector<double> fast, slow, swinging;
  for (int k = 0; k < 100; ++k) {
    fast.push_back(100.0 + 0.5 * std::pow(0.9, k));
    slow.push_back(100.0 + 0.5 * std::pow(0.99, k));
  }
  for (int k = 0; k < 112; ++k) swinging.push_back(100.0 + (k % 2 == 0 ? 0.04 : -0.04));
  EXPECT_TRUE(settled_within(iteration_error(fast), 1e-6));
  EXPECT_FALSE(settled_within(iteration_error(fast), 1e-7));
  EXPECT_TRUE(settled_within(iteration_error(slow), 2e-3));
  EXPECT_FALSE(settled_within(iteration_error(slow), 1e-3));
  const IterationError e = iteration_error(swinging);
  ASSERT_FALSE(e.geometric);
  EXPECT_FALSE(settled_within(e, 5e-4));
  EXPECT_TRUE(settled_within(e, 1e-3));
}
