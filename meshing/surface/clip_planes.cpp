#include "meshing/surface/clip_planes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"

namespace bedforge::meshing {

namespace {

// The height within `shift` of `asked` nearest to it that lies `wanted` clear of every
// obstacle (a z interval); failing that, the clearest one.
struct ClipHeight {
  double z, clearance;
};
ClipHeight clip_height(double asked, double shift, double wanted, const std::vector<std::pair<double, double>>& obstacles) {
  std::vector<std::pair<double, double>> near;
  for (const auto& o : obstacles)
    if (o.second > asked - shift - wanted && o.first < asked + shift + wanted) near.push_back(o);
  auto clearance = [&](double z) {
    double c = std::numeric_limits<double>::infinity();
    for (const auto& [lo, hi] : near) c = std::min(c, z < lo ? lo - z : z > hi ? z - hi : -std::min(z - lo, hi - z));
    return c;
  };
  // Candidates: the asked height, the ends of the range, the midpoints between obstacle ends,
  // and the points `wanted` away from each end (the nearest clear heights).
  std::vector<double> ends{asked - shift, asked + shift}, candidates{asked, asked - shift, asked + shift};
  for (const auto& [lo, hi] : near) ends.push_back(lo), ends.push_back(hi);
  std::sort(ends.begin(), ends.end());
  for (std::size_t k = 0; k + 1 < ends.size(); ++k) candidates.push_back(0.5 * (ends[k] + ends[k + 1]));
  for (double e : ends) candidates.push_back(e - 1.001 * wanted), candidates.push_back(e + 1.001 * wanted);
  ClipHeight best{asked, -std::numeric_limits<double>::infinity()}, nearest{asked, -1.0};
  bool found = false;
  for (double z : candidates) {
    if (std::abs(z - asked) > shift) continue;
    const double c = clearance(z);
    if (c > best.clearance) best = {z, c};
    if (c >= wanted && (!found || std::abs(z - asked) < std::abs(nearest.z - asked))) nearest = {z, c}, found = true;
  }
  return found ? nearest : best;
}

}  // namespace

ClipPlacement place_clip_planes(const Bed& bed, const SurfaceParams& p, DomainPlanes planes,
                                const std::vector<double>& radius, const ContactExtents& extents) {
  const std::size_t n = bed.size();
  const double d = reference_diameter(bed);
  const double d_max = largest_diameter(bed);
  const double clearance = p.clip_clearance_d * d;
  std::vector<std::pair<double, double>> sphere_ends;
  for (std::size_t i = 0; i < n; ++i) {
    const double z = bed.centres[i].z(), r = radius[i];
    for (double e : {z - r, z + r}) sphere_ends.push_back({e, e});
  }
  auto everything = sphere_ends;
  for (const auto& [k, range] : extents) everything.push_back(range);
  // Where no height is clear of the contacts, the spheres' ends at either radius, and the
  // contacts near the plane are opened (shrunk as by the shrink treatment, left as gaps).
  const bool can_open = p.treatment != SurfaceParams::Treatment::enlarge &&
                        p.wall_treatment != SurfaceParams::Treatment::enlarge;
  auto with_shrunk = sphere_ends;
  for (std::size_t i = 0; i < n; ++i) {
    const double z = bed.centres[i].z(), r = 0.5 * p.shrink_factor * bed.diameters[i];
    for (double e : {z - r, z + r}) with_shrunk.push_back({e, e});
  }
  const double moved = (1.0 - p.shrink_factor) * d_max;  // how far a contact's geometry moves when opened
  ClipPlacement out;
  ClipOpening& opening = out.opening;
  opening.spheres.assign(n, 0);
  const DomainPlanes asked = planes;
  for (auto [z, name] : {std::pair<double*, const char*>{&planes.z0, "inlet"}, {&planes.z1, "outlet"}}) {
    ClipHeight h = clip_height(*z, p.clip_shift_d * d, clearance, everything);
    const bool opens = !(h.clearance >= clearance) && can_open;
    if (opens) h = clip_height(*z, p.clip_shift_d * d, clearance, with_shrunk);
    if (!(h.clearance >= clearance))
      throw InputError(fmt::format(
          "surface.clip_window_d: the {} clip plane at {:.4g} d finds no height within surface.clip_shift_d = {} d "
          "that keeps surface.clip_clearance_d = {} d clear of every sphere's top and bottom{} (at best {:.3g} d, at "
          "{:.4g} d); allowed: a larger clip_shift_d or a smaller clip_clearance_d",
          name, *z / d, p.clip_shift_d, p.clip_clearance_d, can_open ? "" : " and every enlarged contact",
          h.clearance / d, h.z / d));
    *z = h.z;
    long opened = 0;
    if (opens)
      for (const auto& [k, range] : extents) {
        if (!(range.first < h.z + clearance + moved && range.second > h.z - clearance - moved)) continue;
        opening.contacts.insert(k);
        const auto [i, j] = contact_of(k, n);
        opening.spheres[i] = 1;
        if (j < n) opening.spheres[j] = 1;
        ++opened;
      }
    out.report[name] = {{"asked_d", (name[0] == 'i' ? asked.z0 : asked.z1) / d}, {"used_d", h.z / d},
                         {"clearance_d", h.clearance / d}, {"contacts_opened", opened}};
  }
  if (!(planes.z1 > planes.z0))
    throw InputError("surface.clip_window_d: the clip planes crossed while moving clear of the bed; allowed: a taller window");
  out.planes = planes;
  return out;
}

}  // namespace bedforge::meshing
