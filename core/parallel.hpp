#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

namespace bedforge {

// Loops over fewer particles than this run on the calling thread alone. Below it a pass costs
// less than waking and joining the other threads, and under load (another process on the
// cores) every join waited for a descheduled thread, so small packs took seconds. The
// crossover and the slowdown are measured in docs/defaults.md ("Threads").
constexpr std::size_t kParallelMinItems = 512;
inline bool worth_threads(std::size_t items) { return items >= kParallelMinItems; }

// f(i) for i in [0, n), split statically over the OpenMP threads when worth_threads(n), else
// on the calling thread without entering OpenMP: a parallel region whose `if` clause is false
// still makes a system call on entry, which cost about a third of an iteration of the packers
// at N = 500 (docs/findings.md, "Per-iteration overheads of small beds").
template <class F>
void parallel_for(std::size_t n, F f) {
  if (!worth_threads(n)) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) f(i);
}

// fold(acc, i) for i in [0, n) into `init`, split like parallel_for: each thread folds its share
// into its own copy of `init`, then merge(total, copy) combines the copies in no fixed order, so
// merge must not depend on order (a maximum, a logical or, the two largest values).
template <class T, class Fold, class Merge>
T parallel_reduce(std::size_t n, T init, Fold fold, Merge merge) {
  T total = init;
  if (!worth_threads(n)) {
    for (std::size_t i = 0; i < n; ++i) fold(total, i);
    return total;
  }
#pragma omp parallel
  {
    T mine = init;
#pragma omp for schedule(static) nowait
    for (std::size_t i = 0; i < n; ++i) fold(mine, i);
#pragma omp critical
    merge(total, mine);
  }
  return total;
}

// Sum of f(i) for i in [0, n), in parallel but in an order fixed by n alone (blocks of a fixed
// size added in block order), so the result does not depend on the number of threads: stopping
// tests built on such sums make the same decisions on every machine.
template <class F>
double deterministic_sum(std::size_t n, F f) {
  constexpr std::size_t kBlock = 2048;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  auto block_sum = [&](std::size_t b) {
    double s = 0.0;
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) s += f(i);
    return s;
  };
  if (blocks <= 1) return blocks ? block_sum(0) : 0.0;  // the same sum without an OpenMP region
  std::vector<double> partial(blocks, 0.0);
#pragma omp parallel for schedule(static)
  for (std::size_t b = 0; b < blocks; ++b) partial[b] = block_sum(b);
  double total = 0.0;
  for (double s : partial) total += s;
  return total;
}

// Per-bin totals of `add(i, acc)` over items i in [0, n) (add accumulates item i's share of
// each bin into acc, `bins` long), in parallel but summed in an order fixed by n alone (chunks
// of items in index order), so reruns on any thread count give identical numbers.
template <class PerItem>
std::vector<double> accumulate_bins(std::size_t n, std::size_t bins, PerItem add) {
  constexpr std::size_t kChunk = 1024;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<double>> partial(chunks, std::vector<double>(bins, 0.0));
#pragma omp parallel for schedule(dynamic) if (chunks > 1)
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) add(i, partial[c]);
  std::vector<double> total(bins, 0.0);
  for (const auto& p : partial)
    for (std::size_t b = 0; b < bins; ++b) total[b] += p[b];
  return total;
}

}  // namespace bedforge
