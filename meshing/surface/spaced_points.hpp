#pragma once
#include <Eigen/Core>

#include <array>
#include <algorithm>
#include <cmath>
#include <functional>
#include <unordered_map>
#include <utility>
#include <vector>

namespace bedforge::meshing {

// Indices of points by the cubic cell of side `cell` that holds each (a hash grid): near(p, visit)
// visits every index in the 27 cells about p's, which hold every point within `cell` of p (and
// some farther, which callers filter by distance).
class PointsByCell {
 public:
  explicit PointsByCell(double cell) : cell_(cell) {}
  void add(const Eigen::Vector3d& p, int index) {
    const auto k = cell_of(p);
    cells_[key(k[0], k[1], k[2])].push_back(index);
  }
  template <class Visit>
  void near(const Eigen::Vector3d& p, const Visit& visit) const {
    const auto k = cell_of(p);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz)
          if (const auto it = cells_.find(key(k[0] + dx, k[1] + dy, k[2] + dz)); it != cells_.end())
            for (int index : it->second) visit(index);
  }

 private:
  std::array<long, 3> cell_of(const Eigen::Vector3d& p) const {
    return {static_cast<long>(std::floor(p.x() / cell_)), static_cast<long>(std::floor(p.y() / cell_)),
            static_cast<long>(std::floor(p.z() / cell_))};
  }
  static long key(long x, long y, long z) { return (x * 73856093L) ^ (y * 19349663L) ^ (z * 83492791L); }
  double cell_;
  std::unordered_map<long, std::vector<int>> cells_;
};

// Candidate mesh vertices (spheres, walls), accepted in order when no accepted vertex lies closer
// than 0.8 x the mean of their spacings (a Poisson-disk rule with local sizes): a uniform grid
// of cell `cell` >= every spacing keeps the test to the 27 neighbouring cells.
class SpacedPoints {
 public:
  explicit SpacedPoints(double cell) : grid_(cell) {}
  bool fits(const Eigen::Vector3d& p, double spacing) const {
    bool fits = true;
    grid_.near(p, [&](int q) { fits = fits && (points[q] - p).norm() >= 0.4 * (spacing + spacing_[q]); });
    return fits;
  }
  void add(const Eigen::Vector3d& p, double spacing) {
    grid_.add(p, static_cast<int>(points.size()));
    points.push_back(p);
    spacing_.push_back(spacing);
  }
  double spacing(int i) const { return spacing_[i]; }
  std::vector<Eigen::Vector3d> points;

 private:
  PointsByCell grid_;
  std::vector<double> spacing_;
};

// Edge length wanted at a point of a surface being meshed (m), between `finest` and the
// mesher's own edge; empty: the mesher's edge everywhere. The meshers take candidate vertices
// `finest` apart where the field asks for less than their edge, finest first.
// Vertices with their spacing (m).
using Seeds = std::vector<std::pair<Eigen::Vector3d, double>>;

struct SpacingField {
  std::function<double(const Eigen::Vector3d&)> at;
  double finest = 0.0;
  // Vertices that sphere_mesh and plane_mesh offer before their other free sites, finest first
  // (so where two patches overlap the finer is kept), with `at` or without: a patch finer than
  // `finest` (end_wedges.hpp).
  Seeds seeds{};
  Seeds seeds_finest_first() const {
    Seeds out = seeds;
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    return out;
  }
  explicit operator bool() const { return static_cast<bool>(at); }
};

// The candidate sites (of any type) that each_site(visit) visits, a lattice of spacing
// field.finest, offered to add(site, spacing) where the field asks (at to_world(site)) for
// less than `coarse`, finest first and then in visiting order: the coarser vertices then grade
// away from the finer ones.
template <class Site>
void offer_finest_first(const SpacingField& field, double coarse,
                        const std::function<void(const std::function<void(const Site&)>&)>& each_site,
                        const std::function<Eigen::Vector3d(const Site&)>& to_world,
                        const std::function<void(const Site&, double)>& add) {
  std::vector<std::pair<double, Site>> asked;
  each_site([&](const Site& q) {
    const double s = field.at(to_world(q));
    if (s < coarse) asked.emplace_back(s, q);
  });
  std::stable_sort(asked.begin(), asked.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [s, q] : asked) add(q, s);
}

// Rings graded away from loops (sphere cuts, wall holes) until their spacing reaches `full`:
// ring by ring across all loops, spacing times `growth` per ring, rings sqrt(3)/2 of their
// mean spacing apart. Calls emit(loop, ring, offset from the loop, spacing); odd rings are
// staggered by the caller.
inline void graded_rings(std::vector<double> spacing, double full, double growth,
                         const std::function<void(std::size_t, int, double, double)>& emit) {
  std::vector<double> offset(spacing.size(), 0.0);
  for (auto& s : spacing) s = std::min(s, full);
  for (int ring = 1;; ++ring) {
    bool any = false;
    for (std::size_t k = 0; k < spacing.size(); ++k) {
      if (ring > 1 && spacing[k] >= full) continue;
      const double next = std::min(full, spacing[k] * growth);
      offset[k] += std::sqrt(3.0) / 2.0 * 0.5 * (spacing[k] + next);
      spacing[k] = next;
      any = true;
      emit(k, ring, offset[k], next);
    }
    if (!any) return;
  }
}

// The closed polyline `loop` resampled at about `spacing` by arc length (at least 6 points),
// starting half a step on when `stagger`.
template <class Point>
std::vector<Point> resample_loop(const std::vector<Point>& loop, double spacing, bool stagger) {
  const std::size_t n = loop.size();
  std::vector<double> at{0.0};
  for (std::size_t k = 0; k < n; ++k) at.push_back(at.back() + (loop[(k + 1) % n] - loop[k]).norm());
  const int count = std::max(6, static_cast<int>(std::lround(at.back() / spacing)));
  std::vector<Point> out;
  std::size_t seg = 0;
  for (int k = 0; k < count; ++k) {
    const double s = (k + (stagger ? 0.5 : 0.0)) * at.back() / count;
    while (seg + 1 < n && at[seg + 1] < s) ++seg;
    const double t = (s - at[seg]) / std::max(at[seg + 1] - at[seg], 1e-300);
    out.push_back(loop[seg] + t * (loop[(seg + 1) % n] - loop[seg]));
  }
  return out;
}

}  // namespace bedforge::meshing
