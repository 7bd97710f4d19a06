#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace bedforge {

// n-point Gauss-Legendre nodes and weights on [-1, 1] (Newton on the Legendre recurrence).
struct GaussLegendre {
  static constexpr int n = 24;
  std::array<double, n> x{}, w{};
  GaussLegendre() {
    for (int i = 0; i < (n + 1) / 2; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = 0.0;
        for (int k = 1; k <= n; ++k) {
          const double p2 = p1;
          p1 = p0;
          p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k;
        }
        dp = n * (z * p0 - p1) / (z * z - 1.0);
        const double dz = p0 / dp;
        z -= dz;
        if (std::abs(dz) < 1e-16) break;
      }
      x[i] = -z, x[n - 1 - i] = z;
      w[i] = w[n - 1 - i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

// Integral over [cuts.front(), cuts.back()] of f(z), by 24-point Gauss-Legendre on each piece
// between consecutive cuts (sorted here); the callers cut where f is not smooth.
template <class F>
double integrate_pieces(std::vector<double> cuts, F f) {
  static const GaussLegendre gl;
  std::sort(cuts.begin(), cuts.end());
  double v = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double mid = 0.5 * (cuts[k] + cuts[k + 1]), half = 0.5 * (cuts[k + 1] - cuts[k]);
    if (half <= 0.0) continue;
    for (int q = 0; q < GaussLegendre::n; ++q) v += half * gl.w[q] * f(mid + half * gl.x[q]);
  }
  return v;
}

}  // namespace bedforge
