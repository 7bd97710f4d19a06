#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "core/intersection_volumes.hpp"
#include "core/quadrature.hpp"
#include "meshing/surface/contact_treatment.hpp"

namespace bedforge::meshing::contact_parts {

std::vector<Wall> walls_of(const Container& c) {
  if (const auto* cyl = dynamic_cast<const Cylinder*>(&c)) return {Wall{"wall", 0, false, cyl->radius()}};
  if (const auto* ann = dynamic_cast<const Annulus*>(&c))
    return {Wall{"wall", 0, false, ann->outer_radius()}, Wall{"inner wall", 1, false, ann->inner_radius(), true}};
  if (const auto* box = dynamic_cast<const Box*>(&c)) {
    // A box periodic on both sides has no walls (build_periodic_box_surface; its period along z
    // may be unwrapped when the fluid domain is sized); one periodic on one side only is not meshed.
    if (box->periodicity().lx > 0.0 && box->periodicity().ly > 0.0) return {};
    if (box->periodicity().lateral())
      throw InputError("container.periodic_x/periodic_y = true: the surface stage meshes a box periodic on every side "
                       "(periodic_x, periodic_y and period_z) or walled on every side; allowed: both periodic_x and "
                       "periodic_y with container.period_z_d, or neither");
    const double hx = 0.5 * box->size_x(), hy = 0.5 * box->size_y();
    auto side = [](const char* name, int index, Eigen::Vector3d n, double k) {
      Wall w{name, index, true};
      w.n = n, w.k = k;
      return w;
    };
    return {side("wall at x min", 0, -Eigen::Vector3d::UnitX(), hx), side("wall at x max", 1, Eigen::Vector3d::UnitX(), hx),
            side("wall at y min", 2, -Eigen::Vector3d::UnitY(), hy), side("wall at y max", 3, Eigen::Vector3d::UnitY(), hy)};
  }
  throw InputError(fmt::format("the surface stage handles cylinder, annulus and box containers; this bed's container "
                               "is a {}",
                               c.kind()));
}

void ContactTreatment::wall(std::size_t i, const Wall& w, const NeighbourList& nl) {
  const Eigen::Vector3d& c = bed_.centres[i];
  const double r = out_.radius[i], gap = w.gap(c, r);
  const std::string who = fmt::format("sphere {} and the {}", i, w.name);
  if (open(key(i, bed_.size() + w.index), who, gap, out_.kept[i], &w)) return;
  const Treatment t = p_.wall_treatment;
  const bool treated = gap < treat_below(t);
  if ((treated && beyond_planes(key(i, bed_.size() + w.index), who)) || !out_.kept[i]) return;
  if (!treated) {
    if (w.gap(c, r / scale_) <= kContact * d_) {
      if (t == Treatment::shrink) ++treated_pw_;
      ++out_.thin_gap_contacts;
    }
    return gap_left(gap, &w, who);
  }
  ++treated_pw_;
  const Eigen::Vector3d a = w.towards(c);
  const double to_wall = w.reach(c);  // centre to wall along a
  auto& holes = out_.wall_holes[w.index];
  if (t == Treatment::cap) {
    const double g = p_.cap_gap_d * d_, h = to_wall - g;
    if (h <= 0.1 * r) throw InputError(fmt::format("{} overlap too deeply to be capped", who));
    const double rho_c = std::sqrt(r * r - h * h);
    const Frame f = plane_cut(i, a, h, rho_c, ring_points(rho_c, edge_c_), 0.0, "cap towards the " + w.name);
    out_.parts.push_back(ring_mesh(f, 0.0, rho_c, edge_c_, 0.0, true, "particles"));
    area_ += kPi * rho_c * rho_c;
    double left = g;  // the disk's rim bends towards a concave wall
    for (const auto& q : out_.cuts[i].back().loop) left = std::min(left, w.reach(q));
    ++caps_;
    return gap_left(left, &w, who);
  }
  const double bridge_radius = 0.5 * p_.bridge_diameter_d * d_;
  if (t == Treatment::enlarge || (gap < 0.0 && std::sqrt(-gap * (2.0 * r + gap)) >= 0.5 * bridge_radius)) return wall_union(i, w, a);
  if (bridge_radius >= 0.9 * r)
    throw InputError(fmt::format("contacts.bridge_diameter_d = {}: a bridge as wide as sphere {} (diameter {:.3g} d); "
                                 "allowed: below 0.9 x the smallest sphere diameter",
                                 p_.bridge_diameter_d, i, 2.0 * r / d_));
  const double h = std::sqrt(r * r - bridge_radius * bridge_radius);
  const auto length_in = [&w](const Frame& f) -> GeneratorLength {
    return [f, w](double x, double y) { return w.hit(f.to_world(Eigen::Vector3d(x, y, 0.0)), f.w); };
  };
  const GeneratorLength axial = length_in(Frame::along(c + h * a, a));
  double shortest = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 64; ++j) {
    const double l = axial(bridge_radius * std::cos(2 * kPi * j / 64), bridge_radius * std::sin(2 * kPi * j / 64));
    shortest = std::min(shortest, std::isnan(l) ? -1.0 : l);
  }
  if (!(shortest > 0.0))
    throw InputError(fmt::format("{}: no room for a bridge (the sphere crosses the wall or the bridge misses it)", who));
  // The tube to a wall is half as long as one between two touching spheres, or less at a concave
  // wall; its edge is shortened in proportion, so that its triangles keep the shape they have
  // between spheres: long thin ones gave dual cells whose centres fell outside their faces, which
  // checkMesh failed (docs/findings.md, 2026-11-29).
  const double edge = edge_c_ * std::min(1.0, shortest / (2.0 * (r - h)));
  const int n = ring_points(bridge_radius, edge);
  const Frame f = plane_cut(i, a, h, bridge_radius, n, kBreakCocircular, "bridge to the " + w.name);
  const GeneratorLength length = length_in(f);
  const Eigen::Vector3d from = f.origin, to = f.origin + length(0.0, 0.0) * a;
  for (int k : nl.of(i))
    if (segment_distance(bed_.centres[k], from, to) < out_.radius[k] + bridge_radius)
      throw InputError(fmt::format("the bridge between {} would cross sphere {}", who, k));
  holes.push_back({tube_end_loop(f, bridge_radius, n, length, edge), 2.0 * kPi * bridge_radius / n, static_cast<int>(i)});
  out_.parts.push_back(tube_mesh(f, bridge_radius, n, length, edge, true, "particles"));
  // Volume and lateral area of the bridge: polar quadrature over its cross-section (smooth
  // integrand: Gauss-Legendre in radius, trapezoid in angle, both spectrally accurate).
  // Between the heights measured: each generator's stretch between them (a kink in the
  // integrand where it reaches one, so less accurate, on a volume a thousandth of a sphere's).
  const auto stretch_between = [&](double x, double y) {
    const double l = length(x, y);
    if (!between_) return 0.0;
    const double z = f.to_world(Eigen::Vector3d(x, y, 0.0)).z(), az = a.z(), z1 = (*between_)[0], z2 = (*between_)[1];
    if (std::abs(az) < 1e-15) return z >= z1 && z <= z2 ? l : 0.0;
    const double ta = (z1 - z) / az, tb = (z2 - z) / az;
    return std::max(0.0, std::min(l, std::max(ta, tb)) - std::max(0.0, std::min(ta, tb)));
  };
  constexpr int kAngles = 128;
  double vol = 0.0, lateral = 0.0, vol_between = 0.0;
  for (int j = 0; j < kAngles; ++j) {
    const double th = 2.0 * kPi * j / kAngles, cs = std::cos(th), sn = std::sin(th);
    lateral += length(bridge_radius * cs, bridge_radius * sn) * bridge_radius * 2.0 * kPi / kAngles;
    vol += integrate_pieces({0.0, bridge_radius}, [&](double s) { return length(s * cs, s * sn) * s; }) * 2.0 * kPi /
           kAngles;
    if (between_)
      vol_between += integrate_pieces({0.0, bridge_radius}, [&](double s) { return stretch_between(s * cs, s * sn) * s; }) *
                     2.0 * kPi / kAngles;
  }
  volume_ += vol;
  between_volume_ += vol_between;
  area_ += lateral;
  wedge(0.5 * kPi + std::asin(bridge_radius / r));
  ++bridges_;
  gap_left(shortest, &w, who);
}

void ContactTreatment::wall_union(std::size_t i, const Wall& w, const Eigen::Vector3d& a) {
  const Eigen::Vector3d& c = bed_.centres[i];
  const double r = out_.radius[i];
  auto& holes = out_.wall_holes[w.index];
  ++unions_;
  if (w.plane) return cross_plane(i, a, w.reach(c), "union with the " + w.name, holes, std::nullopt);
  const Eigen::Vector3d e1 = Eigen::Vector3d::UnitZ(), e2 = a.cross(e1);
  // Polar angle from a of the curve in the direction phi, by bisection.
  auto point = [&](double beta, double phi) {
    return Eigen::Vector3d(c + r * (std::cos(beta) * a + std::sin(beta) * (std::cos(phi) * e1 + std::sin(phi) * e2)));
  };
  auto beta_at = [&](double phi) {
    double lo = 0.0, hi = kPi;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      (w.beyond(point(mid, phi)) ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  };
  constexpr int kAngles = 256;
  double removed_area = 0.0, beta_max = 0.0, perimeter = 0.0;
  for (int j = 0; j < kAngles; ++j) {
    const double b = beta_at(2.0 * kPi * j / kAngles);
    removed_area += r * r * (1.0 - std::cos(b)) * 2.0 * kPi / kAngles;
    perimeter += r * std::sin(b) * 2.0 * kPi / kAngles;
    beta_max = std::max(beta_max, b);
  }
  const int n = std::max(8, static_cast<int>(std::ceil(perimeter / edge_c_)));
  SphereCut cut;
  for (int j = 0; j < n; ++j) {
    const double phi = 2.0 * kPi * j / n;
    cut.loop.push_back(point(beta_at(phi), phi));
  }
  cut.spacing = perimeter / n;
  cut.axis = a;
  cut.removed = [w](const Eigen::Vector3d& q) { return w.beyond(q); };
  cut.fluid_ends = true;
  add_cut(i, std::move(cut), "union with the " + w.name, beta_max);
  open_hole(i, holes, -w.towards(out_.cuts[i].back().loop[0]));
  const double rho = std::hypot(c.x(), c.y());
  const double inside = sphere_cylinder_volume(r, rho, c.z(), w.R, c.z() - r, c.z() + r);
  volume_ -= w.inner ? inside : 4.0 / 3.0 * kPi * r * r * r - inside;
  if (between_) {
    const double z1 = (*between_)[0], z2 = (*between_)[1], in_between = sphere_cylinder_volume(r, rho, c.z(), w.R, z1, z2);
    between_volume_ -= w.inner ? in_between : sphere_slab_volume(r, c.z(), z1, z2) - in_between;
  }
  area_ -= removed_area;
}

void ContactTreatment::open_hole(std::size_t i, std::vector<WallHole>& holes, const Eigen::Vector3d& into_fluid) {
  const SphereCut& cut = out_.cuts[i].back();
  holes.push_back({cut.loop, cut.spacing, static_cast<int>(i)});
  wedge(kPi - std::acos(std::clamp(((cut.loop[0] - bed_.centres[i]) / out_.radius[i]).dot(into_fluid), -1.0, 1.0)));
}

void ContactTreatment::cross_plane(std::size_t i, const Eigen::Vector3d& a, double h, const std::string& name,
                 std::vector<WallHole>& holes, std::optional<Eigen::Vector3d> at) {
  const double r = out_.radius[i], rho = std::sqrt(std::max(0.0, r * r - h * h));
  plane_cut(i, a, h, rho, ring_points(rho, edge_c_), kBreakCocircular, name, at);
  out_.cuts[i].back().fluid_ends = true;
  open_hole(i, holes, -a);
}

void ContactTreatment::ends(std::size_t i) {
  const double z = bed_.centres[i].z(), r = out_.radius[i], z0_ = planes_.z0, z1_ = planes_.z1;
  if (planes_.clip) {
    if (out_.kept[i] && z - r < z0_) clip(i, false);
    if (out_.kept[i] && z + r > z1_) clip(i, true);
    return;
  }
  if (z - r <= z0_ || z + r >= z1_)
    throw InputError(fmt::format("sphere {} reaches the {} plane (surface.{}_length_d = {}); allowed: a longer "
                                 "empty section",
                                 i, z - r <= z0_ ? "inlet" : "outlet", z - r <= z0_ ? "inlet" : "outlet",
                                 z - r <= z0_ ? p_.inlet_length_d : p_.outlet_length_d));
}

void ContactTreatment::clip(std::size_t i, bool outlet) {
  const Eigen::Vector3d& c = bed_.centres[i];
  const double z = outlet ? planes_.z1 : planes_.z0, h = outlet ? z - c.z() : c.z() - z;
  const Eigen::Vector3d a = outlet ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
  cross_plane(i, a, h, outlet ? "outlet clip plane" : "inlet clip plane", outlet ? out_.outlet_holes : out_.inlet_holes,
              Eigen::Vector3d(c.x(), c.y(), z));
  const double r0 = 0.5 * bed_.diameters[i], H0 = std::clamp(r0 - h, 0.0, 2.0 * r0);
  volume0_ -= cap_volume(r0, H0);
  between_volume0_ -= cap_between(c, r0, a, r0 - H0);
  area0_ -= cap_area(r0, H0);
}

}  // namespace bedforge::meshing::contact_parts
