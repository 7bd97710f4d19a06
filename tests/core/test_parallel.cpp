#include "core/parallel.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <vector>

using bedforge::deterministic_sum;
using bedforge::kParallelMinItems;
using bedforge::parallel_for;
using bedforge::parallel_reduce;

namespace {

// Values whose sum depends on the order of addition (magnitudes from 1e-8 to 1e8).
double value(std::size_t i) { return std::pow(10.0, static_cast<double>(i % 17) - 8.0) * (i % 3 == 0 ? -1.0 : 1.0); }

// Runs f on `threads` OpenMP threads and restores the previous count.
template <class F>
auto on_threads(int threads, F f) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  auto result = f();
  omp_set_num_threads(before);
  return result;
}

}  // namespace

TEST(Parallel, DeterministicSumIsTheSameOnOneAndTwoThreads) {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{500}, std::size_t{2048}, std::size_t{100001}}) {
    const double one = on_threads(1, [&] { return deterministic_sum(n, value); });
    const double two = on_threads(2, [&] { return deterministic_sum(n, value); });
    EXPECT_EQ(one, two) << "n = " << n;  // bit for bit, not within a tolerance
    double serial = 0.0;  // blocks of 2048 in order: below one block, the plain running sum
    if (n <= 2048) {
      for (std::size_t i = 0; i < n; ++i) serial += value(i);
      EXPECT_EQ(one, serial) << "n = " << n;
    }
  }
}

TEST(Parallel, ParallelForVisitsEveryIndexOnceBelowAndAboveTheThreadThreshold) {
  for (std::size_t n : {std::size_t{7}, kParallelMinItems - 1, kParallelMinItems, std::size_t{50000}}) {
    std::vector<int> visits(n, 0);
    on_threads(2, [&] {
      parallel_for(n, [&](std::size_t i) { ++visits[i]; });
      return 0;
    });
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(visits[i], 1) << "index " << i << " of " << n;
  }
}

TEST(Parallel, ParallelReduceFindsTheTwoLargestOnAnyThreadCount) {
  struct TwoLargest {
    double first = -1.0, second = -1.0;
  };
  auto keep = [](double v, TwoLargest& t) {
    if (v > t.first) t.second = t.first, t.first = v;
    else if (v > t.second) t.second = v;
  };
  for (std::size_t n : {std::size_t{10}, std::size_t{100000}}) {
    // A permutation of 0..n-1 (3 and n coprime) whose two largest sit at n/3 and 2n/3, in
    // different threads' halves on two threads, so the merge has to combine them.
    auto at = [n](std::size_t i) { return static_cast<double>((i * 3) % n); };
    for (int threads : {1, 2}) {
      const TwoLargest t = on_threads(threads, [&] {
        return parallel_reduce(
            n, TwoLargest{}, [&](TwoLargest& m, std::size_t i) { keep(at(i), m); },
            [&](TwoLargest& total, const TwoLargest& m) {
              keep(m.first, total);
              keep(m.second, total);
            });
      });
      EXPECT_EQ(t.first, static_cast<double>(n - 1)) << n << " on " << threads;
      EXPECT_EQ(t.second, static_cast<double>(n - 2)) << n << " on " << threads;
    }
  }
}
