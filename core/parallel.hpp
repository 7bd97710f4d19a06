#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

namespace bedforge {

// Sum of f(i) for i in [0, n), in parallel but in an order fixed by n alone (blocks of a fixed
// size added in block order), so the result does not depend on the number of threads: stopping
// tests built on such sums make the same decisions on every machine.
template <class F>
double deterministic_sum(std::size_t n, F f) {
  constexpr std::size_t kBlock = 2048;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<double> partial(blocks, 0.0);
#pragma omp parallel for schedule(static)
  for (std::size_t b = 0; b < blocks; ++b) {
    double s = 0.0;
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) s += f(i);
    partial[b] = s;
  }
  double total = 0.0;
  for (double s : partial) total += s;
  return total;
}

}  // namespace bedforge
