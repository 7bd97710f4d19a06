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
  const double h = 2.0 * r_max + skin_;
  const Eigen::Vector4d b = container.lateral_bounds();
  const Periodicity per = container.periodicity();
  // Along a periodic axis the grid spans one period (centres are wrapped into [0, L)).
  double z_lo = per.lz > 0.0 ? 0.0 : x[0].z(), z_hi = per.lz > 0.0 ? per.lz : x[0].z();
  if (per.lz == 0.0)
    for (const auto& p : x) z_lo = std::min(z_lo, p.z()), z_hi = std::max(z_hi, p.z());
  const long nx = std::max(1L, static_cast<long>((b[2] - b[0]) / h)), ny = std::max(1L, static_cast<long>((b[3] - b[1]) / h));
  const double hx = (b[2] - b[0]) / static_cast<double>(nx), hy = (b[3] - b[1]) / static_cast<double>(ny);
  // Cap the number of layers so a bed thrown apart (before a divergence is caught) cannot ask
  // for an unbounded grid; cells then grow taller, which only costs time.
  const long max_nz = std::max(1L, static_cast<long>(4 * n / static_cast<std::size_t>(nx * ny)) + 1);
  // A periodic axis has whole cells of at least h across the period, as the sides have.
  const long nz = per.lz > 0.0 ? std::max(1L, static_cast<long>(per.lz / h))
                               : std::clamp(static_cast<long>((z_hi - z_lo) / h) + 1, 1L, max_nz);
  const double hz = per.lz > 0.0 ? per.lz / static_cast<double>(nz)
                                 : std::max(h, (z_hi - z_lo) / static_cast<double>(nz) * (1.0 + 1e-12));
  auto clampi = [](double v, long hi) { return std::clamp(static_cast<long>(std::floor(v)), 0L, hi - 1); };
  auto cell_of = [&](const Eigen::Vector3d& p, long& cx, long& cy, long& cz) {  // p wrapped
    cx = clampi((p.x() - b[0]) / hx, nx);
    cy = clampi((p.y() - b[1]) / hy, ny);
    cz = clampi((p.z() - z_lo) / hz, nz);
  };

  // Counting sort of spheres by cell (stable: spheres keep index order inside a cell).
  const long cells = nx * ny * nz;
  std::vector<long>& cell = cell_;
  std::vector<std::size_t>& start = start_;
  cell.resize(n);
  start.assign(static_cast<std::size_t>(cells) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    long cx, cy, cz;
    cell_of(per.wrapped(x[i]), cx, cy, cz);
    cell[i] = (cz * ny + cy) * nx + cx;
    ++start[static_cast<std::size_t>(cell[i]) + 1];
  }
  for (long c = 0; c < cells; ++c) start[c + 1] += start[c];
  // Centres and radii copied in cell order: the cells X-1..X+1 of a row are adjacent in this
  // order, so each sphere scans 9 contiguous runs of memory instead of 27 scattered cells
  // (a 1e5-sphere bed: 30-45 % less time per build).
  std::vector<int>& sorted = sorted_;
  sorted.resize(n);
  in_cells_.resize(n);
  {
    std::vector<std::size_t>& fill = fill_;
    fill.assign(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t k = fill[cell[i]]++;
      sorted[k] = static_cast<int>(i);
      in_cells_[k] << per.wrapped(x[i]), r[i];
    }
  }

  // One pass over the surrounding cells into rows of fixed capacity (grown and redone on
  // overflow, which only wide size mixtures need), then packed into the compact list.
  for (bool overflow = true; overflow;) {
    overflow = false;
    scratch_.resize(n * capacity_);
#pragma omp parallel for schedule(dynamic, 256) reduction(|| : overflow) if (worth_threads(n))
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p = per.wrapped(x[i]);
      long cx, cy, cz;
      cell_of(p, cx, cy, cz);
      std::size_t count = 0;
      int* list = scratch_.data() + i * capacity_;
      auto scan = [&](long row, long first, long last) {  // cells first..last of a row
        for (std::size_t k = start[row * nx + first]; k < start[row * nx + last + 1]; ++k) {
          const Eigen::Vector4d& q = in_cells_[k];
          const double reach = r[i] + q.w() + skin_;
          if (per.separation(q.head<3>(), p).squaredNorm() >= reach * reach || sorted[k] == static_cast<int>(i)) continue;
          if (count < capacity_) list[count] = sorted[k];
          ++count;
        }
      };
      // The neighbouring cells along one axis, in order; a periodic axis wraps around, and with
      // fewer than 3 cells across a wrapped cell is taken once.
      auto around = [](long c, long count, bool periodic, long* out) {
        long m = 0;
        for (long d = -1; d <= 1; ++d) {
          long v = c + d;
          if (periodic) v = (v + count) % count;
          if (v < 0 || v >= count || std::find(out, out + m, v) != out + m) continue;
          out[m++] = v;
        }
        return m;
      };
      long zs[3], ys[3], xs[3];
      const long mz = around(cz, nz, per.lz > 0.0, zs), my = around(cy, ny, per.ly > 0.0, ys), mx = around(cx, nx, per.lx > 0.0, xs);
      for (long kz = 0; kz < mz; ++kz)
        for (long ky = 0; ky < my; ++ky) {
          const long row = zs[kz] * ny + ys[ky];
          // Adjacent cells of the row are scanned as one run.
          for (long first = 0, last = 0; first < mx; first = last + 1) {
            last = first;
            while (last + 1 < mx && xs[last + 1] == xs[last] + 1) ++last;
            scan(row, xs[first], xs[last]);
          }
        }
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
