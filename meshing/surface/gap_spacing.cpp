#include "meshing/surface/gap_spacing.hpp"

#include <algorithm>
#include <cmath>

namespace bedforge::meshing {

namespace {

double largest(const std::vector<double>& radii) {
  return radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end());
}

}  // namespace

// Gaps wider than cells_per_gap * coarsest ask for the coarsest edge: spheres farther than that
// do not matter, so a cell of the largest radius plus that reach holds every sphere that does
// within the 27 cells around a point.
GapSpacing::GapSpacing(const std::vector<Eigen::Vector3d>& centres, const std::vector<double>& radii,
                       const std::vector<char>& kept, const Container& container, double cells_per_gap,
                       double finest, double coarsest)
    : centres_(centres), radii_(radii), kept_(kept), container_(container), cells_(cells_per_gap), finest_(finest),
      coarsest_(coarsest), grid_(largest(radii) + cells_per_gap * coarsest) {
  for (std::size_t i = 0; i < centres.size(); ++i)
    if (kept[i]) grid_.add(centres[i], static_cast<int>(i));
}

double GapSpacing::gap(const Eigen::Vector3d& p, int self) const {
  const double reach = cells_ * coarsest_;
  double gap = reach;
  grid_.near(p, [&](int j) {
    if (j != self) gap = std::min(gap, std::max(0.0, (p - centres_[j]).norm() - radii_[j]));
  });
  return self >= 0 ? std::min(gap, wall_distance(p)) : gap;
}

double GapSpacing::wall_distance(const Eigen::Vector3d& p) const {
  // A wall within reach overlaps the sphere of radius `reach` about p by reach - distance.
  const double reach = cells_ * coarsest_;
  WallContact walls[Container::kMaxWallContacts];
  const int n = container_.wall_contacts(p, reach, walls);
  double distance = reach;
  for (int k = 0; k < n; ++k) distance = std::min(distance, std::max(0.0, reach - walls[k].overlap));
  return distance;
}

double GapSpacing::at(const Eigen::Vector3d& p, int self) const {
  return std::clamp(gap(p, self) / cells_, finest_, coarsest_);
}

double GapSpacing::medial_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& n, int self) const {
  // Where the ray p + t n is as far from sphere j's surface as from self's (t): |a + t n| = t + r_j.
  double t = 0.5 * cells_ * coarsest_;
  grid_.near(p, [&](int j) {
    if (j == self) return;
    const Eigen::Vector3d a = p - centres_[j];
    const double towards = radii_[j] - a.dot(n);
    if (towards > 0.0) t = std::min(t, std::max(0.0, a.squaredNorm() - radii_[j] * radii_[j]) / (2.0 * towards));
  });
  // The walls: where the ray's distance to the nearest wall falls to t, by bisection (that
  // distance less t decreases along the ray).
  auto nearer_wall = [&](double s) { return wall_distance(p + s * n) < s; };
  if (nearer_wall(t)) {
    double lo = 0.0, hi = t;
    for (int k = 0; k < 30; ++k) (nearer_wall(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    t = hi;
  }
  return t;
}

std::vector<double> GapSpacing::added_cells_profile(double volume_per_cell, double z0, double z1, int bins) const {
  const double pi = std::acos(-1.0), golden_angle = pi * (3.0 - std::sqrt(5.0));
  const double per_coarsest = 1.0 / (volume_per_cell * coarsest_ * coarsest_ * coarsest_);
  const long n = static_cast<long>(centres_.size());
  std::vector<double> profile(bins, 0.0);
  double* total = profile.data();
  const double per_bin = (z1 - z0) / bins;
#pragma omp parallel for reduction(+ : total[:bins]) schedule(dynamic, 8)
  for (long i = 0; i < n; ++i) {
    if (!kept_[i]) continue;
    // A Fibonacci lattice whose spacing is a third of the smallest refined patch's radius.
    const double r = radii_[i], area = 4.0 * pi * r * r;
    const double spacing = std::sqrt(cells_ * finest_ * r) / 3.0;
    const long m = std::clamp(static_cast<long>(area / (spacing * spacing)), 500L, 200000L);
    for (long k = 0; k < m; ++k) {
      const double z = 1.0 - (2.0 * static_cast<double>(k) + 1.0) / static_cast<double>(m);
      const double rho = std::sqrt(1.0 - z * z), phi = golden_angle * static_cast<double>(k);
      const Eigen::Vector3d normal(rho * std::cos(phi), rho * std::sin(phi), z), p = centres_[i] + r * normal;
      if (p.z() < z0 || p.z() > z1) continue;
      const double edge = std::clamp(gap(p, static_cast<int>(i)) / cells_, finest_, coarsest_);
      if (edge >= coarsest_) continue;
      // The column out to the medial surface widens with the sphere.
      const double t = medial_distance(p, normal, static_cast<int>(i)), widening = 1.0 + t / r;
      const double column = r / 3.0 * (widening * widening * widening - 1.0);
      const int bin = std::min(bins - 1, static_cast<int>((p.z() - z0) / per_bin));
      total[bin] += area / static_cast<double>(m) * column * (1.0 / (volume_per_cell * edge * edge * edge) - per_coarsest);
    }
  }
  return profile;
}

}  // namespace bedforge::meshing
