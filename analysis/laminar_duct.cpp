#include "analysis/laminar_duct.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bedforge::analysis {

double laminar_duct_gradient(const Container& container, double viscosity, double velocity) {
  const double mu_u = viscosity * velocity;
  if (const auto* cyl = dynamic_cast<const Cylinder*>(&container)) {
    const double r = cyl->radius();
    return 8.0 * mu_u / (r * r);
  }
  if (const auto* ann = dynamic_cast<const Annulus*>(&container)) {
    const double r_o = ann->outer_radius(), r_i = ann->inner_radius();
    const double a2 = r_o * r_o, b2 = r_i * r_i;
    return 8.0 * mu_u / (a2 + b2 - (a2 - b2) / std::log(r_o / r_i));
  }
  if (const auto* box = dynamic_cast<const Box*>(&container)) {
    const double b = 0.5 * std::max(box->size_x(), box->size_y()), c = 0.5 * std::min(box->size_x(), box->size_y());
    const double pi = std::acos(-1.0);
    double sum = 0.0;
    for (int i = 1;; i += 2) {
      const double term = std::tanh(i * pi * b / (2.0 * c)) / std::pow(i, 5);
      sum += term;
      if (term < 1e-16 * sum) break;
    }
    const double s = 1.0 - 192.0 * c / (std::pow(pi, 5) * b) * sum;
    return 3.0 * mu_u / (c * c * s);
  }
  throw std::logic_error("laminar_duct_gradient: container kind " + container.kind() + " has no exact solution here");
}

}  // namespace bedforge::analysis
