#include "core/neighbour_list.hpp"

#include <algorithm>
#include <cmath>

namespace bedforge {

bool NeighbourList::update(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r,
                           const Container& container) {
  bool stale = built_at_.size() != x.size();
  if (!stale) {
    const double limit2 = 0.25 * skin_ * skin_;
#pragma omp parallel for schedule(static) reduction(|| : stale)
    for (std::size_t i = 0; i < x.size(); ++i) stale = stale || (x[i] - built_at_[i]).squaredNorm() > limit2;
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
  double z_lo = x[0].z(), z_hi = x[0].z();
  for (const auto& p : x) z_lo = std::min(z_lo, p.z()), z_hi = std::max(z_hi, p.z());
  const long nx = std::max(1L, static_cast<long>((b[2] - b[0]) / h)), ny = std::max(1L, static_cast<long>((b[3] - b[1]) / h));
  const double hx = (b[2] - b[0]) / static_cast<double>(nx), hy = (b[3] - b[1]) / static_cast<double>(ny);
  // Cap the number of layers so a bed thrown apart (before a divergence is caught) cannot ask
  // for an unbounded grid; cells then grow taller, which only costs time.
  const long max_nz = std::max(1L, static_cast<long>(4 * n / static_cast<std::size_t>(nx * ny)) + 1);
  const long nz = std::clamp(static_cast<long>((z_hi - z_lo) / h) + 1, 1L, max_nz);
  const double hz = std::max(h, (z_hi - z_lo) / static_cast<double>(nz) * (1.0 + 1e-12));
  auto clampi = [](double v, long hi) { return std::clamp(static_cast<long>(std::floor(v)), 0L, hi - 1); };
  const Periodicity per = container.periodicity();
  auto cell_of = [&](const Eigen::Vector3d& q, long& cx, long& cy, long& cz) {
    const Eigen::Vector3d p = per.wrapped(q);
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
    cell_of(x[i], cx, cy, cz);
    cell[i] = (cz * ny + cy) * nx + cx;
    ++start[static_cast<std::size_t>(cell[i]) + 1];
  }
  for (long c = 0; c < cells; ++c) start[c + 1] += start[c];
  std::vector<int>& sorted = sorted_;
  sorted.resize(n);
  {
    std::vector<std::size_t>& fill = fill_;
    fill.assign(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) sorted[fill[cell[i]]++] = static_cast<int>(i);
  }

  // One pass over the 27 surrounding cells into rows of fixed capacity (grown and redone on
  // overflow, which only wide size mixtures need), then packed into the compact list.
  for (bool overflow = true; overflow;) {
    overflow = false;
    scratch_.resize(n * capacity_);
#pragma omp parallel for schedule(dynamic, 256) reduction(|| : overflow)
    for (std::size_t i = 0; i < n; ++i) {
      long cx, cy, cz;
      cell_of(x[i], cx, cy, cz);
      std::size_t count = 0;
      int* row = scratch_.data() + i * capacity_;
      for (long dz = -1; dz <= 1; ++dz)
        for (long dy = -1; dy <= 1; ++dy)
          for (long dx = -1; dx <= 1; ++dx) {
            long X = cx + dx, Y = cy + dy;
            const long Z = cz + dz;
            // Periodic sides wrap around; with fewer than 3 cells across, a wrapped cell would
            // be visited twice, so only the first visit counts.
            if (per.lx > 0.0) {
              X = (X + nx) % nx;
              if (nx < 3 && dx != -1 && (X == (cx - 1 + nx) % nx || (dx == 1 && X == cx))) continue;
            }
            if (per.ly > 0.0) {
              Y = (Y + ny) % ny;
              if (ny < 3 && dy != -1 && (Y == (cy - 1 + ny) % ny || (dy == 1 && Y == cy))) continue;
            }
            if (X < 0 || Y < 0 || Z < 0 || X >= nx || Y >= ny || Z >= nz) continue;
            const long c = (Z * ny + Y) * nx + X;
            for (std::size_t k = start[c]; k < start[c + 1]; ++k) {
              const int j = sorted[k];
              if (static_cast<std::size_t>(j) == i) continue;
              const double reach = r[i] + r[j] + skin_;
              if (per.separation(x[j], x[i]).squaredNorm() >= reach * reach) continue;
              if (count < capacity_) row[count] = j;
              ++count;
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
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i)
    std::copy_n(scratch_.data() + i * capacity_, offsets_[i + 1] - offsets_[i], list_.data() + offsets_[i]);
}

}  // namespace bedforge
