#include "packer/hard_sphere_chain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bedforge::packer {

HardSphereChain::HardSphereChain(const Container& c, double d_max, double grid_height, double lid, std::uint64_t seed)
    : c_(c), per_(c.periodicity()), lid_(lid), rng_(seed) {
  bounds_ = c.lateral_bounds();
  nx_ = std::max(1L, static_cast<long>((bounds_[2] - bounds_[0]) / d_max));
  ny_ = std::max(1L, static_cast<long>((bounds_[3] - bounds_[1]) / d_max));
  hx_ = (bounds_[2] - bounds_[0]) / static_cast<double>(nx_);
  hy_ = (bounds_[3] - bounds_[1]) / static_cast<double>(ny_);
  d_max_ = d_max;
  if (per_.lz > 0.0) {
    lid_ = std::numeric_limits<double>::infinity();
    grid_period();
    return;
  }
  hz_ = d_max;
  nz_ = std::clamp(static_cast<long>(grid_height / d_max) + 1, 1L, 1L << 20);
  cells_.assign(static_cast<std::size_t>(nx_ * ny_ * nz_), {});
}

void HardSphereChain::grid_period() {
  nz_ = std::clamp(static_cast<long>(per_.lz / d_max_), 1L, 1L << 20);
  hz_ = per_.lz / static_cast<double>(nz_);
  cells_.assign(static_cast<std::size_t>(nx_ * ny_ * nz_), {});
  for (std::size_t i = 0; i < cell_of_.size(); ++i) insert(static_cast<int>(i), cell_index(x_[i]));
}

bool HardSphereChain::add(const Eigen::Vector3d& q, double r, double w) {
  const int i = static_cast<int>(x_.size());
  const Eigen::Vector3d p = per_.wrapped(q);
  x_.push_back(p);
  r_.push_back(r);
  w_.push_back(w);
  if (inside(i, p) && !overlaps_any(i, p)) {
    cell_of_.push_back(0);
    slot_.push_back(0);
    insert(i, cell_index(p));
    return true;
  }
  x_.pop_back();
  r_.pop_back();
  w_.pop_back();
  return false;
}

long HardSphereChain::cell_index(const Eigen::Vector3d& q) const {
  const Eigen::Vector3d p = per_.wrapped(q);
  auto clampi = [](double v, long n) { return std::clamp(static_cast<long>(std::floor(v)), 0L, n - 1); };
  const long cx = clampi((p.x() - bounds_[0]) / hx_, nx_), cy = clampi((p.y() - bounds_[1]) / hy_, ny_),
             cz = clampi(p.z() / hz_, nz_);
  return (cz * ny_ + cy) * nx_ + cx;
}

void HardSphereChain::insert(int i, long cell) {
  cell_of_[i] = cell;
  slot_[i] = static_cast<int>(cells_[cell].size());
  cells_[cell].push_back(i);
}

void HardSphereChain::remove(int i) {
  auto& v = cells_[cell_of_[i]];
  const int last = v.back();
  v[slot_[i]] = last;
  slot_[last] = slot_[i];
  v.pop_back();
}

bool HardSphereChain::inside(int i, const Eigen::Vector3d& p) const {
  if (per_.lz == 0.0 && (p.z() < r_[i] || p.z() > lid_ - r_[i])) return false;
  WallContact w[Container::kMaxWallContacts];
  return c_.wall_contacts(p, r_[i], w) == 0;
}

template <class Visit>
bool HardSphereChain::near(long cell, long layers, Visit visit) const {
  const long cx = cell % nx_, cy = (cell / nx_) % ny_, cz = cell / (nx_ * ny_);
  // Along a periodic side the grid wraps; with too few cells across, every cell of that row is
  // a neighbour and must be visited once.
  auto range = [](long c, long n, long reach, bool periodic, long& lo, long& hi) {
    if (periodic && n < 2 * reach + 1) lo = 0, hi = n - 1;
    else lo = c - reach, hi = c + reach;
  };
  long x0, x1, y0, y1, z0, z1;
  range(cx, nx_, 1, per_.lx > 0.0, x0, x1);
  range(cy, ny_, 1, per_.ly > 0.0, y0, y1);
  range(cz, nz_, layers, per_.lz > 0.0, z0, z1);
  // Without a period along z the top layer holds everything above it: a sphere there may
  // touch any sphere in the layer.
  auto wrap = [](long c, long n, bool periodic, long& out) {
    if (periodic) out = (c % n + n) % n;
    else if (c < 0 || c >= n) return false;
    else out = c;
    return true;
  };
  for (long Z = z0; Z <= z1; ++Z)
    for (long Y = y0; Y <= y1; ++Y)
      for (long X = x0; X <= x1; ++X) {
        long xx, yy, zz;
        if (!wrap(X, nx_, per_.lx > 0.0, xx) || !wrap(Y, ny_, per_.ly > 0.0, yy) || !wrap(Z, nz_, per_.lz > 0.0, zz))
          continue;
        for (int j : cells_[(zz * ny_ + yy) * nx_ + xx])
          if (visit(j)) return true;
      }
  return false;
}

bool HardSphereChain::overlaps_any(int i, const Eigen::Vector3d& p) const {
  return near(cell_index(p), 1, [&](int j) {
    const double reach = r_[i] + r_[j];
    return j != i && per_.separation(p, x_[j]).squaredNorm() < reach * reach;
  });
}

double HardSphereChain::feasible_compression() const {
  // Scaling heights by s brings a pair (dx, dy, dz) into contact when
  // dx^2 + dy^2 + s^2 dz^2 = (r_i + r_j)^2; two layers reach |dz| up to 2 d_max, beyond which
  // no pair can touch for s >= 0.5.
  double s = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i)
    near(cell_of_[i], 2, [&](int j) {
      if (j <= static_cast<int>(i)) return false;
      const Eigen::Vector3d sep = per_.separation(x_[i], x_[j]);
      const double reach = r_[i] + r_[j], lateral = sep.x() * sep.x() + sep.y() * sep.y();
      if (lateral < reach * reach && sep.z() != 0.0)
        s = std::max(s, std::sqrt((reach * reach - lateral) / (sep.z() * sep.z())));
      return false;
    });
  return s;
}

void HardSphereChain::compress_to(double period) {
  const double s = period / per_.lz;
  per_.lz = period;
  for (auto& q : x_) q = per_.wrapped(Eigen::Vector3d(q.x(), q.y(), q.z() * s));
  grid_period();
}

double HardSphereChain::cycle(double temperature, bool gravity) {
  std::size_t accepted = 0;
  const double inv_t = 1.0 / temperature;
  for (std::size_t k = 0; k < x_.size(); ++k) {
    const int i = static_cast<int>(k);
    const Eigen::Vector3d step(delta_ * (2.0 * rng_.uniform() - 1.0), delta_ * (2.0 * rng_.uniform() - 1.0),
                               delta_ * (2.0 * rng_.uniform() - 1.0));
    // Metropolis on the gravitational energy first: it is free, and at low T most uphill
    // trials end here without a neighbour search. The uniform is drawn for every trial so the
    // random stream does not depend on the outcome.
    const double u = rng_.uniform();
    if (gravity && step.z() > 0.0 && u >= std::exp(-w_[i] * step.z() * inv_t)) continue;
    const Eigen::Vector3d p = per_.wrapped(x_[i] + step);
    if (!inside(i, p) || overlaps_any(i, p)) continue;
    x_[i] = p;
    const long cell = cell_index(p);
    if (cell != cell_of_[i]) {
      remove(i);
      insert(i, cell);
    }
    ++accepted;
  }
  return x_.empty() ? 0.0 : static_cast<double>(accepted) / static_cast<double>(x_.size());
}

void HardSphereChain::adapt_displacement(double acceptance, double target, double lo, double hi) {
  delta_ = std::clamp(delta_ * (acceptance > target ? 1.05 : 0.95), lo, hi);
}

void HardSphereChain::lift(double height, double dilation) {
  double top = 0.0;
  for (const auto& q : x_) top = std::max(top, q.z());
  const double stretch = top > 0.0 ? dilation * height / top : 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    x_[i].z() += height + stretch * x_[i].z();
    const long cell = cell_index(x_[i]);
    if (cell != cell_of_[i]) {
      remove(static_cast<int>(i));
      insert(static_cast<int>(i), cell);
    }
  }
}

double HardSphereChain::mass_centre() const {
  double wz = 0.0, w = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) wz += w_[i] * x_[i].z(), w += w_[i];
  return w > 0.0 ? wz / w : 0.0;
}

}  // namespace bedforge::packer
