#include "packer/generation.hpp"

#include <cmath>
#include <numbers>

namespace bedforge::packer {

double generate_initial_bed(Spheres& s, const Container& container, double eps0, Rng& rng) {
  double volume = 0.0;
  for (double r : s.r) volume += 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double L0 = volume / (container.cross_section_area() * (1.0 - eps0));
  s.x.resize(s.r.size());
  for (std::size_t i = 0; i < s.r.size(); ++i) {
    const Eigen::Vector2d xy = container.sample_centre(rng, s.r[i]);
    s.x[i] = {xy.x(), xy.y(), L0 * rng.uniform() + s.r[i]};
  }
  return L0;
}

}  // namespace bedforge::packer
