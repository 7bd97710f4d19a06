#include "core/neighbour_list.hpp"

#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"

namespace bedforge {

bool NeighbourList::update(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r,
                           const Container& container) {
  bool stale = built_at_.size() != x.size();
  if (!stale) {
    // A pair's gap has shrunk by at most the sum of the two spheres' displacements, so the list
    // holds every touching pair while the two largest displacements sum to less than the skin
    // (the usual rule, twice the largest, rebuilds sooner; on packed beds the two rebuild about as
    // often, since whole regions move together).
    auto keep_two_largest = [](double m, double& first, double& second) {
      if (m > first) {
        second = first;
        first = m;
      } else if (m > second) {
        second = m;
      }
    };
    struct TwoLargest {
      double first = 0.0, second = 0.0;  // squared displacements
    };
    const TwoLargest moved = parallel_reduce(
        x.size(), TwoLargest{},
        [&](TwoLargest& m, std::size_t i) { keep_two_largest((x[i] - built_at_[i]).squaredNorm(), m.first, m.second); },
        [&](TwoLargest& total, const TwoLargest& m) {
          keep_two_largest(m.first, total.first, total.second);
          keep_two_largest(m.second, total.first, total.second);
        });
    stale = std::sqrt(moved.first) + std::sqrt(moved.second) > skin_;
  }
  if (stale) build(x, r, container);
  return stale;
}

void NeighbourList::build(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r,
                          const Container& container) {
  const std::size_t n = x.size();
  ++builds_;
  built_at_.assign(x.begin(), x.end());
  offsets_.assign(n + 1, 0);
  list_.clear();
  if (n == 0) return;

  const double r_max = *std::max_element(r.begin(), r.end());
  grid_.build(x, r, container, 2.0 * r_max + skin_);
  const Periodicity per = container.periodicity();

  // One pass over the surrounding cells into rows of fixed capacity (grown and redone on
  // overflow, which only wide size mixtures need), then packed into the compact list.
  for (bool overflow = true; overflow;) {
    overflow = false;
    scratch_.resize(n * capacity_);
#pragma omp parallel for schedule(dynamic, 256) reduction(|| : overflow) if (worth_threads(n))
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p = per.wrapped(x[i]);
      std::size_t count = 0;
      int* list = scratch_.data() + i * capacity_;
      grid_.for_each_run_around(p, [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) {
          const Eigen::Vector4d& q = grid_.centre_and_radius(k);
          const double reach = r[i] + q.w() + skin_;
          if (per.separation(q.head<3>(), p).squaredNorm() >= reach * reach || grid_.sphere(k) == static_cast<int>(i))
            continue;
          if (count < capacity_) list[count] = grid_.sphere(k);
          ++count;
        }
      });
      offsets_[i + 1] = count;
      overflow = overflow || count > capacity_;
    }
    if (overflow) {
      std::size_t most = 0;
      for (std::size_t i = 0; i < n; ++i) most = std::max(most, offsets_[i + 1]);
      capacity_ = 2 * most;
    }
  }
  for (std::size_t i = 0; i < n; ++i) offsets_[i + 1] += offsets_[i];
  list_.resize(offsets_[n]);
#pragma omp parallel for schedule(static) if (worth_threads(n))
  for (std::size_t i = 0; i < n; ++i)
    std::copy_n(scratch_.data() + i * capacity_, offsets_[i + 1] - offsets_[i], list_.data() + offsets_[i]);
}

}  // namespace bedforge
