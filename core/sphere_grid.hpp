#pragma once
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/container.hpp"

namespace bedforge {

// Sphere centres sorted by the cell they lie in, on a grid of cells at least `h` wide over the
// container's lateral bounds and the centres' heights (whole cells over one period along a
// periodic axis), so that every centre within h of a point lies in the 27 cells around the
// point's: near spheres are found in O(1) per point. Building is O(N) and allocates nothing when
// rebuilt at the same size (the packers rebuild it often).
class SphereGrid {
 public:
  // x: centres, r: radii (N each); h: the least cell width (the same length unit). Points outside
  // the grid (beyond the centres' heights) fall into its outer cells.
  void build(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r, const Container& container, double h);

  // Calls run(begin, end) for the positions [begin, end) (see sphere, centre_and_radius) of the
  // spheres in the cells around p (wrapped into the central cell: Periodicity::wrapped), every
  // cell once, in a fixed order: layer by layer, row by row, and the adjacent cells of a row as
  // one run (contiguous memory).
  template <class Run>
  void for_each_run_around(const Eigen::Vector3d& p, Run&& run) const {
    if (sorted_.empty()) return;
    long cx, cy, cz;
    cell_of(p, cx, cy, cz);
    long zs[3], ys[3], xs[3];
    const long mz = around(cz, nz_, per_.lz > 0.0, zs), my = around(cy, ny_, per_.ly > 0.0, ys),
               mx = around(cx, nx_, per_.lx > 0.0, xs);
    for (long kz = 0; kz < mz; ++kz)
      for (long ky = 0; ky < my; ++ky) {
        const long row = zs[kz] * ny_ + ys[ky];
        for (long first = 0, last = 0; first < mx; first = last + 1) {
          last = first;
          while (last + 1 < mx && xs[last + 1] == xs[last] + 1) ++last;
          run(start_[row * nx_ + xs[first]], start_[row * nx_ + xs[last] + 1]);
        }
      }
  }
  int sphere(std::size_t k) const { return sorted_[k]; }  // the sphere at position k
  // Its centre (wrapped into the central periodic cell) and radius.
  const Eigen::Vector4d& centre_and_radius(std::size_t k) const { return in_cells_[k]; }

 private:
  // p wrapped; each index clamped into the grid.
  void cell_of(const Eigen::Vector3d& p, long& cx, long& cy, long& cz) const {
    auto clampi = [](double v, long hi) { return std::clamp(static_cast<long>(std::floor(v)), 0L, hi - 1); };
    cx = clampi((p.x() - bounds_[0]) / hx_, nx_);
    cy = clampi((p.y() - bounds_[1]) / hy_, ny_);
    cz = clampi((p.z() - z_lo_) / hz_, nz_);
  }
  // The cells c - 1, c, c + 1 along one axis of `count`, in order, into `out`; a periodic axis
  // wraps around, and with fewer than 3 cells across a wrapped cell is taken once.
  static long around(long c, long count, bool periodic, long* out) {
    long m = 0;
    for (long d = -1; d <= 1; ++d) {
      long v = c + d;
      if (periodic) v = (v + count) % count;
      if (v < 0 || v >= count || std::find(out, out + m, v) != out + m) continue;
      out[m++] = v;
    }
    return m;
  }

  Periodicity per_;
  Eigen::Vector4d bounds_ = Eigen::Vector4d::Zero();  // the container's lateral bounds
  double z_lo_ = 0.0, hx_ = 1.0, hy_ = 1.0, hz_ = 1.0;
  long nx_ = 1, ny_ = 1, nz_ = 1;
  std::vector<std::size_t> start_;        // cell c holds positions [start_[c], start_[c + 1])
  std::vector<int> sorted_;               // sphere at each position
  std::vector<Eigen::Vector4d> in_cells_; // centre and radius at each position
  std::vector<long> cell_;                // work arrays of build()
  std::vector<std::size_t> fill_;
};

}  // namespace bedforge
