#include "meshing/surface/end_wedges.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "core/random.hpp"
#include "meshing/surface/primitives.hpp"

namespace bedforge::meshing {

std::vector<EndNearPlane> ends_near_planes(const std::vector<Eigen::Vector3d>& centres,
                                           const std::vector<double>& radii, const std::vector<double>& planes_z,
                                           double coarse) {
  std::vector<EndNearPlane> out;
  const double reach = coarse / kWedgeEdgePerGap;
  for (double z : planes_z)
    for (std::size_t i = 0; i < centres.size(); ++i)
      for (bool above : {true, false}) {
        const EndNearPlane e{z, centres[i], radii[i], above, static_cast<int>(i)};
        if (e.gap() != 0.0 && std::abs(e.gap()) < reach) out.push_back(e);
      }
  std::sort(out.begin(), out.end(), [](const EndNearPlane& a, const EndNearPlane& b) {
    return std::tuple(a.plane_z, a.centre.x(), a.centre.y(), a.above) <
           std::tuple(b.plane_z, b.centre.x(), b.centre.y(), b.above);
  });
  return out;
}

std::vector<SphereNearPlane> spheres_near_planes(const std::vector<Eigen::Vector3d>& centres,
                                                 const std::vector<double>& radii,
                                                 const std::vector<double>& planes_z, double reach) {
  std::vector<SphereNearPlane> out;
  for (std::size_t i = 0; i < centres.size(); ++i)
    if (std::any_of(planes_z.begin(), planes_z.end(),
                    [&](double z) { return std::abs(centres[i].z() - z) < radii[i] + reach; }))
      out.push_back({centres[i], radii[i]});
  std::sort(out.begin(), out.end(), [](const SphereNearPlane& a, const SphereNearPlane& b) {
    return std::tuple(a.centre.x(), a.centre.y(), a.centre.z()) < std::tuple(b.centre.x(), b.centre.y(), b.centre.z());
  });
  return out;
}

std::vector<std::pair<double, double>> end_rings(const EndNearPlane& e, double coarse) {
  const double r = e.radius, gap = e.gap();
  // The gap between the plane and the sphere at distance rho from the end's axis; inside the loop
  // of a plane that cuts the sphere, and near it, the cut's depth.
  auto gap_at = [&](double rho) { return std::max(std::abs(gap), gap + r - std::sqrt(std::max(0.0, r * r - rho * rho))); };
  std::vector<std::pair<double, double>> rings{{0.0, kWedgeEdgePerGap * std::abs(gap)}};
  for (;;) {
    const auto [rho, spacing] = rings.back();
    const double next = rho + std::sqrt(3.0) / 2.0 * spacing;
    const double s = kWedgeEdgePerGap * gap_at(next);
    if (!(s < coarse) || next >= r) return rings;
    rings.emplace_back(next, s);
  }
}

namespace {

// The rings' points: (distance from the axis, angle, spacing), each ring turned by half a step
// against the one inside it, and by `turn` steps more.
template <class Visit>
void each_ring_point(const EndNearPlane& e, double coarse, double turn, const Visit& visit) {
  const auto rings = end_rings(e, coarse);
  visit(0.0, 0.0, rings.front().second);
  for (std::size_t k = 1; k < rings.size(); ++k) {
    const auto [rho, spacing] = rings[k];
    const int n = std::max(6, static_cast<int>(std::ceil(2.0 * std::numbers::pi * rho / spacing)));
    const double step = 2.0 * std::numbers::pi / n;
    for (int j = 0; j < n; ++j) visit(rho, (j + 0.5 * static_cast<double>(k % 2) + turn) * step, spacing);
  }
}

}  // namespace

Seeds sphere_end_seeds(const EndNearPlane& e, double coarse) {
  // Regular rings hold four points on a circle again and again; each moves at random (the same
  // every run) by up to kBreakCocircular / 2 of its spacing, as a sphere's other rings do.
  Rng nudge(1);
  Seeds out;
  const double sign = e.above ? -1.0 : 1.0;
  each_ring_point(e, coarse, 0.0, [&](double rho, double angle, double spacing) {
    const double along = std::sqrt(std::max(0.0, e.radius * e.radius - rho * rho));
    Eigen::Vector3d p = e.centre + Eigen::Vector3d(rho * std::cos(angle), rho * std::sin(angle), sign * along);
    if (rho > 0.0) {
      p += kBreakCocircular * spacing * Eigen::Vector3d(nudge.uniform() - 0.5, nudge.uniform() - 0.5, nudge.uniform() - 0.5);
      p = e.centre + e.radius * (p - e.centre).normalized();
    }
    out.emplace_back(p, spacing);
  });
  return out;
}

Seeds plane_end_seeds(const EndNearPlane& e, double coarse) {
  Seeds out;
  each_ring_point(e, coarse, 0.5, [&](double rho, double angle, double spacing) {
    out.emplace_back(Eigen::Vector3d(e.centre.x() + rho * std::cos(angle), e.centre.y() + rho * std::sin(angle), e.plane_z),
                     spacing);
  });
  return out;
}

std::vector<EndNearPlane> ends_at(const std::vector<EndNearPlane>& ends, double z, double coarse) {
  std::vector<EndNearPlane> out;
  for (const EndNearPlane& e : ends)
    if (std::abs(e.plane_z - z) <= 1e-9 * coarse) out.push_back(e);
  return out;
}

Seeds plane_end_seeds(const std::vector<EndNearPlane>& ends, double coarse) {
  Seeds out;
  for (const EndNearPlane& e : ends)
    for (const auto& seed : plane_end_seeds(e, coarse)) out.push_back(seed);
  return out;
}

}  // namespace bedforge::meshing
