#pragma once
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "core/container.hpp"
#include "core/random.hpp"

namespace bedforge::packer {

// Metropolis Monte Carlo of hard spheres under gravity in a container (Abreu et al. 1999,
// Eqs. 1-5 as re-derived in docs/monte_carlo.md). Canonical ensemble, energy
//   E = sum_i w_i z_i   (+ infinity for any overlap with a sphere, a wall, the floor or the lid),
// in packing units: lengths in reference diameters d, energies in m*_ref g d, where
// w_i = m*_i / m*_ref and m*_i = (rho_i - rho_f) V_i is the buoyancy-corrected mass. A trial
// moves one sphere by a uniform random vector in the cube [-delta, delta]^3 and is accepted with
// probability min(1, exp(-dE / T)), T = kT / (m*_ref g d).
//
// Hard-sphere tests use a cell grid with cells at least one largest diameter wide, so a trial
// looks at the 27 cells around it: O(1) per move, O(N) per cycle.
class HardSphereChain {
 public:
  // An empty chain in `c` (packing units). `d_max`: largest diameter to come (sets the grid);
  // `grid_height`: height the grid covers (anything above shares its top layer); `lid`: height
  // of a closed top (infinity for none); `seed`: the chain's random stream. A container periodic
  // along z (c.axial_period() > 0) has neither floor nor lid: the grid covers one period and
  // wraps, and `grid_height` and `lid` are not used.
  HardSphereChain(const Container& c, double d_max, double grid_height, double lid, std::uint64_t seed);

  // Adds a sphere (centre p, radius r, relative effective mass w) if it lies inside and
  // overlaps nothing; returns whether it was added.
  bool add(const Eigen::Vector3d& p, double r, double w);
  std::size_t size() const { return x_.size(); }

  // One cycle: one trial move per sphere, in index order. `gravity` off gives E = 0 (mixing).
  // Returns the fraction of trials accepted.
  double cycle(double temperature, bool gravity);

  // Adapts delta by 5 % towards `target` acceptance, within [lo, hi].
  void adapt_displacement(double acceptance, double target, double lo, double hi);
  double displacement() const { return delta_; }
  void set_displacement(double delta) { delta_ = delta; }

  // Raises every sphere by `height` and stretches the bed upwards by `dilation` x `height` in
  // proportion to each centre's height (a shake; see monte_carlo.hpp). Never creates an overlap.
  void lift(double height, double dilation);
  void set_lid(double lid) { lid_ = lid; }

  // Along a periodic axis: the period, and the least factor s by which every height and the
  // period can be scaled (z -> s z) without two spheres overlapping (0 when no pair stands in
  // the way). Pairs are sought up to two grid layers apart, so s is exact down to 0.5.
  double period() const { return per_.lz; }
  double feasible_compression() const;
  // Scales every height and the period to `period` (at least period() x feasible_compression()).
  void compress_to(double period);

  const std::vector<Eigen::Vector3d>& positions() const { return x_; }
  // sum w_i z_i / sum w_i: the mass centre, whose drop measures settling.
  double mass_centre() const;

 private:
  std::vector<Eigen::Vector3d> x_;
  std::vector<double> r_, w_;
  const Container& c_;
  Periodicity per_;
  double lid_;
  Rng rng_;
  double delta_ = 0.1;
  // Cell grid over the lateral bounds and [0, z_top); the top layer also holds everything above.
  Eigen::Vector4d bounds_;
  long nx_ = 1, ny_ = 1, nz_ = 1;
  double hx_ = 1, hy_ = 1, hz_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<long> cell_of_;  // per sphere
  std::vector<int> slot_;      // position of the sphere in its cell's vector

  double d_max_;
  long cell_index(const Eigen::Vector3d& p) const;
  // The grid over one period along a periodic axis: layers at least d_max_ high.
  void grid_period();
  // Calls visit(j) for each sphere in the cells within `layers` grid layers of `cell` and one
  // cell across (every cell of a periodic row shorter than 2 layers + 1), until it returns true;
  // returns whether it did.
  template <class Visit>
  bool near(long cell, long layers, Visit visit) const;
  void insert(int i, long cell);
  void remove(int i);
  bool overlaps_any(int i, const Eigen::Vector3d& p) const;
  bool inside(int i, const Eigen::Vector3d& p) const;
};

}  // namespace bedforge::packer
