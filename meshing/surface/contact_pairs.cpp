#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "meshing/surface/contact_treatment.hpp"

namespace bedforge::meshing::contact_parts {

void ContactTreatment::pair(std::size_t i, std::size_t j, const NeighbourList& nl) {
  const Eigen::Vector3d &ci = bed_.centres[i], &cj = bed_.centres[j];
  const double ri = out_.radius[i], rj = out_.radius[j], dist = (cj - ci).norm(), gap = dist - ri - rj;
  const std::string who = fmt::format("spheres {} and {}", i, j);
  if (open(key(i, j), who, gap, out_.kept[i] && out_.kept[j], nullptr)) return;
  const bool treated = gap < treat_below(p_.treatment);
  if ((treated && beyond_planes(key(i, j), who)) || !out_.kept[i] || !out_.kept[j]) return;
  if (!treated) {
    if (dist - (ri + rj) / scale_ <= kContact * d_) {
      if (p_.treatment == Treatment::shrink) ++treated_pp_;
      ++out_.thin_gap_contacts;
    }
    return gap_left(gap, nullptr, who);
  }
  const Eigen::Vector3d a = (cj - ci) / dist;
  ++treated_pp_;
  if (p_.treatment == Treatment::cap) {
    const double g = p_.cap_gap_d * d_, mid = 0.5 * (dist + ri - rj), cut_i = mid - 0.5 * g, cut_j = dist - mid - 0.5 * g;
    if (cut_i <= 0.1 * ri || cut_j <= 0.1 * rj)
      throw InputError(fmt::format("{} overlap too deeply to be capped (centre distance {:.3g} d)", who, dist / d_));
    // The two disks face each other across a gap thinner than their edges: the same layout on
    // both would put four points in a plane across it again and again, and gmsh's tetrahedra
    // on them have no volume; the second disk is turned by half a rim step.
    for (auto [k, h, axis, steps] : {std::tuple{i, cut_i, a, 0.0}, std::tuple{j, cut_j, Eigen::Vector3d(-a), 0.5}}) {
      const double r = out_.radius[k], rho = std::sqrt(r * r - h * h);
      const int n = ring_points(rho, edge_c_);
      const Frame f = plane_cut(k, axis, h, rho, n, 0.0, fmt::format("cap towards sphere {}", k == i ? j : i),
                                std::nullopt, steps * 2.0 * kPi / n);
      out_.parts.push_back(ring_mesh(f, 0.0, rho, edge_c_, 0.0, true, "particles"));
      area_ += kPi * rho * rho;
    }
    ++caps_;
    return gap_left(g, nullptr, who);
  }
  const double bridge_radius = 0.5 * p_.bridge_diameter_d * d_;
  const double rho_union = gap < 0.0 ? std::sqrt(std::max(0.0, ri * ri - std::pow((dist * dist + ri * ri - rj * rj) / (2.0 * dist), 2))) : 0.0;
  if (p_.treatment == Treatment::enlarge || rho_union >= 0.5 * bridge_radius) {
    // Union along the circle where the spheres meet (the radical plane).
    const double cut_i = (dist * dist + ri * ri - rj * rj) / (2.0 * dist), cut_j = dist - cut_i;
    if (cut_i <= 0.0 || cut_j <= 0.0)
      throw InputError(fmt::format("{} overlap so deeply that one centre lies inside the other sphere", who));
    const double rho = std::sqrt(std::max(0.0, ri * ri - cut_i * cut_i));
    const int n = ring_points(rho, edge_c_);
    const Frame f = plane_cut(i, a, cut_i, rho, n, kBreakCocircular, fmt::format("union with sphere {}", j));
    SphereCut cut;
    cut.loop = out_.cuts[i].back().loop;  // the same vertices on both spheres
    cut.spacing = out_.cuts[i].back().spacing;
    cut.axis = -a;
    cut.removed = [ci, a, cut_i](const Eigen::Vector3d& q) { return (q - ci).dot(a) < cut_i; };
    add_cut(j, std::move(cut), fmt::format("union with sphere {}", i), std::acos(std::clamp(cut_j / rj, -1.0, 1.0)));
    volume_ -= cap_volume(rj, rj - cut_j);
    between_volume_ -= cap_between(cj, rj, -a, cut_j);
    area_ -= cap_area(rj, rj - cut_j);
    const Eigen::Vector3d q = f.to_world(Eigen::Vector3d(rho, 0.0, 0.0));
    wedge(kPi - std::acos(std::clamp(((q - ci) / ri).dot((q - cj) / rj), -1.0, 1.0)));
    ++unions_;
    return;
  }
  if (bridge_radius >= 0.9 * std::min(ri, rj))
    throw InputError(fmt::format("contacts.bridge_diameter_d = {}: a bridge as wide as the smaller of {} (diameter "
                                 "{:.3g} d); allowed: below 0.9 x the smallest sphere diameter",
                                 p_.bridge_diameter_d, who, 2.0 * std::min(ri, rj) / d_));
  const double cut_i = std::sqrt(ri * ri - bridge_radius * bridge_radius), cut_j = std::sqrt(rj * rj - bridge_radius * bridge_radius), L = dist - cut_i - cut_j;
  if (!(L > 0.0)) throw InputError(fmt::format("{}: no room for a bridge between them", who));
  const Eigen::Vector3d from = ci + cut_i * a, to = ci + (cut_i + L) * a;
  for (std::size_t s : {i, j})
    for (int k : nl.of(s))
      if (static_cast<std::size_t>(k) != i && static_cast<std::size_t>(k) != j &&
          segment_distance(bed_.centres[k], from, to) < out_.radius[k] + bridge_radius)
        throw InputError(fmt::format("the bridge between {} would cross sphere {}; allowed: a narrower "
                                     "contacts.bridge_diameter_d or another treatment",
                                     who, k));
  const int n = ring_points(bridge_radius, edge_c_);
  const Frame f = plane_cut(i, a, cut_i, bridge_radius, n, kBreakCocircular, fmt::format("bridge to sphere {}", j));
  const GeneratorLength length = [L](double, double) { return L; };
  SphereCut cut;
  cut.loop = tube_end_loop(f, bridge_radius, n, length, edge_c_);
  cut.spacing = 2.0 * kPi * bridge_radius / n;
  cut.axis = -a;
  cut.removed = [centre_j = cj, a, cut_j](const Eigen::Vector3d& q) { return (q - centre_j).dot(-a) > cut_j; };
  add_cut(j, std::move(cut), fmt::format("bridge to sphere {}", i), std::acos(std::clamp(cut_j / rj, -1.0, 1.0)));
  volume_ += kPi * bridge_radius * bridge_radius * L - cap_volume(rj, rj - cut_j);
  between_volume_ += between(from, a, 0.0, L, [bridge_radius](double) { return bridge_radius; }) -
                     cap_between(cj, rj, -a, cut_j);
  area_ += 2.0 * kPi * bridge_radius * L - cap_area(rj, rj - cut_j);
  out_.parts.push_back(tube_mesh(f, bridge_radius, n, length, edge_c_, true, "particles"));
  wedge(0.5 * kPi + std::asin(bridge_radius / std::max(ri, rj)));
  ++bridges_;
  gap_left(L, nullptr, who);
}

}  // namespace bedforge::meshing::contact_parts
