#include "core/sphere_grid.hpp"

namespace bedforge {

void SphereGrid::build(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& container,
                       double h) {
  const std::size_t n = x.size();
  sorted_.clear();
  in_cells_.clear();
  if (n == 0) return;
  bounds_ = container.lateral_bounds();
  per_ = container.periodicity();
  // Along a periodic axis the grid spans one period (centres are wrapped into [0, L)).
  z_lo_ = per_.lz > 0.0 ? 0.0 : x[0].z();
  double z_hi = per_.lz > 0.0 ? per_.lz : x[0].z();
  if (per_.lz == 0.0)
    for (const auto& p : x) z_lo_ = std::min(z_lo_, p.z()), z_hi = std::max(z_hi, p.z());
  nx_ = std::max(1L, static_cast<long>((bounds_[2] - bounds_[0]) / h));
  ny_ = std::max(1L, static_cast<long>((bounds_[3] - bounds_[1]) / h));
  hx_ = (bounds_[2] - bounds_[0]) / static_cast<double>(nx_);
  hy_ = (bounds_[3] - bounds_[1]) / static_cast<double>(ny_);
  // Cap the number of layers so a bed thrown apart (before a divergence is caught) cannot ask
  // for an unbounded grid; cells then grow taller, which only costs time.
  const long max_nz = std::max(1L, static_cast<long>(4 * n / static_cast<std::size_t>(nx_ * ny_)) + 1);
  // A periodic axis has whole cells of at least h across the period, as the sides have.
  nz_ = per_.lz > 0.0 ? std::max(1L, static_cast<long>(per_.lz / h))
                      : std::clamp(static_cast<long>((z_hi - z_lo_) / h) + 1, 1L, max_nz);
  hz_ = per_.lz > 0.0 ? per_.lz / static_cast<double>(nz_)
                      : std::max(h, (z_hi - z_lo_) / static_cast<double>(nz_) * (1.0 + 1e-12));

  // Counting sort of spheres by cell (stable: spheres keep index order inside a cell).
  const long cells = nx_ * ny_ * nz_;
  cell_.resize(n);
  start_.assign(static_cast<std::size_t>(cells) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    long cx, cy, cz;
    cell_of(per_.wrapped(x[i]), cx, cy, cz);
    cell_[i] = (cz * ny_ + cy) * nx_ + cx;
    ++start_[static_cast<std::size_t>(cell_[i]) + 1];
  }
  for (long c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  // Centres and radii copied in cell order: the cells X-1..X+1 of a row are adjacent in this
  // order, so a point's neighbours lie in 9 contiguous runs of memory instead of 27 scattered cells
  // (a 1e5-sphere bed's neighbour list: 30-45 % less time per build).
  sorted_.resize(n);
  in_cells_.resize(n);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = fill_[cell_[i]]++;
    sorted_[k] = static_cast<int>(i);
    in_cells_[k] << per_.wrapped(x[i]), r[i];
  }
}

}  // namespace bedforge
