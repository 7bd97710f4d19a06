#include "analysis/contact_statistics.hpp"

#include <algorithm>
#include <cmath>

#include "core/neighbour_list.hpp"
#include "core/parallel.hpp"

namespace bedforge::analysis {

ContactStatistics contact_statistics(const Bed& bed, double gap_tolerance) {
  const std::size_t n = bed.size();
  ContactStatistics st;
  st.sphere_contacts.assign(n, 0);
  st.wall_contacts.assign(n, 0);
  st.floor_contact.assign(n, 0);
  if (n == 0) return st;
  std::vector<double> r(n);
  double r_max = 0.0;
  for (std::size_t i = 0; i < n; ++i) r[i] = 0.5 * bed.diameters[i], r_max = std::max(r_max, r[i]);

  NeighbourList nl(std::max(gap_tolerance, 1e-9 * r_max));
  nl.build(bed.centres, r, *bed.container);
  std::vector<Eigen::Vector3d> push(n);  // sum of overlap * outward normal, m
  std::vector<double> weight(n);
  double max_pair = 0, max_wall = 0, max_floor = 0;
  const Periodicity per = bed.container->periodicity();
#pragma omp parallel for schedule(static) reduction(max : max_pair, max_wall, max_floor) if (worth_threads(n))
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& xi = bed.centres[i];
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int j : nl.of(i)) {
      const Eigen::Vector3d d = per.separation(xi, bed.centres[j]);
      const double dist = d.norm(), gap = dist - r[i] - r[j];
      if (gap <= gap_tolerance) ++st.sphere_contacts[i];
      if (gap < 0.0) {
        max_pair = std::max(max_pair, -gap);
        if (dist > 0.0) p += -gap * d / dist;
      }
    }
    // A wall "contact" within the tolerance: probe with the radius grown by the tolerance.
    WallContact w[Container::kMaxWallContacts];
    const int nw = bed.container->wall_contacts(xi, r[i] + gap_tolerance, w);
    for (int k = 0; k < nw; ++k) {
      ++st.wall_contacts[i];
      const double overlap = w[k].overlap - gap_tolerance;
      if (overlap > 0.0) {
        max_wall = std::max(max_wall, overlap);
        p += overlap * w[k].normal;
      }
    }
    if (per.lz == 0.0) {  // a periodic axis has no floor
      st.floor_contact[i] = xi.z() - r[i] <= gap_tolerance;
      max_floor = std::max(max_floor, r[i] - xi.z());
    }
    push[i] = p;
    weight[i] = r[i] * r[i] * r[i];
  }
  st.max_pair_overlap = max_pair;
  st.max_wall_overlap = max_wall;
  st.max_floor_penetration = std::max(0.0, max_floor);

  if (per.lz > 0.0) return st;  // packed without gravity: no weight to balance, no residual

  // Best-fit stiffness k: minimise sum |F_i / w_i|^2 with F_i = k push_i - w_i z, leaving out
  // the vertical component of spheres on the floor (the floor supplies it), then measure.
  auto part = [&](std::size_t i, const Eigen::Vector3d& v) {
    return st.floor_contact[i] ? Eigen::Vector3d(v.x(), v.y(), 0.0) : v;
  };
  const double num = deterministic_sum(n, [&](std::size_t i) { return part(i, push[i]).z() / weight[i]; });
  const double den = deterministic_sum(n, [&](std::size_t i) { return part(i, push[i]).squaredNorm() / (weight[i] * weight[i]); });
  const double k = den > 0.0 ? num / den : 0.0;
  std::vector<double> rel(n);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d f = k * push[i];
    f.z() -= weight[i];
    if (st.floor_contact[i] && f.z() < 0.0) f.z() = 0.0;
    rel[i] = f.norm() / weight[i];
  }
  st.residual_rms = std::sqrt(deterministic_sum(n, [&](std::size_t i) { return rel[i] * rel[i]; }) / n);
  st.residual_max = *std::max_element(rel.begin(), rel.end());
  return st;
}

SlabCoordination slab_coordination(const Bed& bed, const ContactStatistics& cs, double z_lo, double z_hi) {
  SlabCoordination out;
  long contacts = 0;
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const double z = bed.centres[i].z();
    if (z < z_lo || z > z_hi) continue;
    ++out.spheres;
    contacts += cs.sphere_contacts[i];
    out.rattlers += is_rattler(cs, i);
  }
  if (out.spheres > 0) out.mean_sphere_contacts = static_cast<double>(contacts) / static_cast<double>(out.spheres);
  return out;
}

}  // namespace bedforge::analysis
