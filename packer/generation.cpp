#include "packer/generation.hpp"

#include <cmath>
#include <algorithm>
#include <numeric>

namespace bedforge::packer {

Generated generate_initial_bed(Spheres& s, const Container& container, double eps0, Rng& rng) {
  // Along a periodic axis the spheres fill one period; their density is the period's.
  const double period = container.axial_period();
  const double L0 = period > 0.0 ? period : initial_height(s, container, eps0);
  s.x.resize(s.r.size());
  for (std::size_t i = 0; i < s.r.size(); ++i) {
    const Eigen::Vector2d xy = container.sample_centre(rng, s.r[i]);
    s.x[i] = {xy.x(), xy.y(), L0 * rng.uniform() + (period > 0.0 ? 0.0 : s.r[i])};
  }
  // Number the spheres from the bottom up. Packing moves them by a small part of the bed height,
  // so neighbours keep nearby indices and the force loop reads memory almost in order: for
  // 1e5 spheres this alone makes an iteration several times faster.
  std::vector<std::size_t> order(s.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return s.x[a].z() < s.x[b].z(); });
  Spheres sorted;
  for (std::size_t i : order) {
    sorted.x.push_back(s.x[i]);
    sorted.r.push_back(s.r[i]);
    sorted.w.push_back(s.w[i]);
  }
  s = std::move(sorted);
  return {L0, order};
}

}  // namespace bedforge::packer
