#include "meshing/surface/clip_planes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <regex>
#include <string>

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
  const double reach = opening_reach(bed, p);
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
        if (!reaches_plane(range, h.z, reach)) continue;
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

double piece_margin_d(const Bed& bed, const SurfaceParams& surface) {
  return 3.0 * largest_diameter(bed) / reference_diameter(bed) + surface.cells_per_gap * surface.edge_length_d +
         surface.clip_shift_d;
}

std::vector<double> survey_stretches(const Bed& bed, std::size_t spheres) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> out{-inf};
  if (spheres > 0 && bed.size() > 2 * spheres) {
    std::vector<double> z;
    for (const Eigen::Vector3d& c : bed.centres) z.push_back(c.z());
    std::sort(z.begin(), z.end());
    for (std::size_t k = spheres; k + spheres <= z.size(); k += spheres)
      if (z[k] > out.back()) out.push_back(z[k]);
  }
  out.push_back(inf);
  return out;
}

std::vector<double> treated_heights(const Bed& bed, const SurfaceParams& p, std::size_t spheres_per_window) {
  const double inf = std::numeric_limits<double>::infinity(), d = reference_diameter(bed);
  const double margin = piece_margin_d(bed, p) * d;
  const std::vector<double> stretches = survey_stretches(bed, spheres_per_window);
  std::vector<double> out;
  for (std::size_t s = 0; s + 1 < stretches.size(); ++s) {
    const double lo = stretches[s], hi = stretches[s + 1];
    const CutWindow w = survey_window(bed, p, lo - margin, hi + margin);
    const TreatedBed treated = treat_contacts(w.bed, p, {-inf, inf, false});
    for (std::size_t i = 0; i < w.bed.size(); ++i) {
      if (const double z = w.bed.centres[i].z(); !(z >= lo && z < hi)) continue;  // another stretch's
      for (const SphereCut& cut : treated.cuts[i]) {
        const auto [low, high] = std::minmax_element(cut.loop.begin(), cut.loop.end(),
                                                     [](const auto& a, const auto& b) { return a.z() < b.z(); });
        if (low != cut.loop.end()) out.push_back(low->z()), out.push_back(high->z());
      }
      for (double end : {-treated.radius[i], treated.radius[i]}) out.push_back(w.bed.centres[i].z() + end);
    }
  }
  return out;
}

CutWindow spheres_between(const Bed& bed, const SurfaceParams& p, double lo, double hi) {
  const double inf = std::numeric_limits<double>::infinity();
  CutWindow out;
  out.bed.container = bed.container;
  out.bed.reference_diameter_m = reference_diameter(bed);
  for (std::size_t i = 0; i < bed.size(); ++i)
    if (const double z = bed.centres[i].z(); z >= lo && z <= hi) {
      out.bed.centres.push_back(bed.centres[i]);
      out.bed.diameters.push_back(bed.diameters[i]);
      out.numbers.push_back(i);
    }
  out.surface = p;
  // The whole bed's narrowest wall gap, unless given: a window of every sphere (the periodic
  // cut's) finds it in its own survey, so the bed is treated for it only when spheres were left out.
  if (out.bed.size() < bed.size() && !(p.ring_wall_gap_m > 0.0))
    out.surface.ring_wall_gap_m = treat_contacts(bed, p, {-inf, inf, false}).min_concave_wall_gap;
  return out;
}

ClearHeights plane_clear_heights_d(const Bed& bed, const SurfaceParams& p, bool through_contacts) {
  const double d = reference_diameter(bed);
  // The spheres' surface is at the shrunk radius where shrink treats them all.
  const bool shrunk_all = p.treatment == SurfaceParams::Treatment::shrink;
  ClearHeights h;
  for (std::size_t i = 0; i < bed.size(); ++i) {
    const double z = bed.centres[i].z(), r = 0.5 * bed.diameters[i], shrunk = p.shrink_factor * r;
    const double surface = shrunk_all ? shrunk : r;
    h.sphere_ends.insert(h.sphere_ends.end(), {(z - surface) / d, (z + surface) / d});
    h.all.insert(h.all.end(), {(z - r) / d, (z + r) / d, (z - shrunk) / d, (z + shrunk) / d});
  }
  if (through_contacts)
    for (double z : treated_heights(bed, p)) h.all.push_back(z / d);
  std::sort(h.all.begin(), h.all.end());
  std::sort(h.sphere_ends.begin(), h.sphere_ends.end());
  return h;
}

double widest_interval_middle(const ClearHeights& heights, double asked, double shift, double avoid, double clearance) {
  const std::vector<double>& all = heights.all;
  // The distance from z to the nearest sphere end.
  const auto to_ends = [&](double z) {
    const auto above = std::lower_bound(heights.sphere_ends.begin(), heights.sphere_ends.end(), z);
    double nearest = std::numeric_limits<double>::infinity();
    if (above != heights.sphere_ends.end()) nearest = *above - z;
    if (above != heights.sphere_ends.begin()) nearest = std::min(nearest, z - *std::prev(above));
    return nearest;
  };
  double best = asked, widest = -1.0;
  bool best_clear = false;
  for (std::size_t j = 0; j + 1 < all.size(); ++j) {
    const double mid = 0.5 * (all[j] + all[j + 1]), width = all[j + 1] - all[j];
    if ((all[j] <= avoid && avoid <= all[j + 1]) || std::abs(mid - asked) > shift) continue;
    const bool clear = to_ends(mid) >= clearance;
    if ((clear && !best_clear) || (clear == best_clear && width > widest)) best = mid, widest = width, best_clear = clear;
  }
  return best;
}

CutWindow window_for_cuts(const Bed& bed, const SurfaceParams& p, double lo, double hi, std::vector<double> rings_d) {
  const double d = reference_diameter(bed), inf = std::numeric_limits<double>::infinity();
  CutWindow out = spheres_between(bed, p, lo, hi);
  double lowest = inf, highest = -inf;
  for (std::size_t i = 0; i < out.bed.size(); ++i) {
    lowest = std::min(lowest, out.bed.centres[i].z() - 0.5 * out.bed.diameters[i]);
    highest = std::max(highest, out.bed.centres[i].z() + 0.5 * out.bed.diameters[i]);
  }
  const double pad = 0.5 * largest_diameter(bed);
  SurfaceParams& q = out.surface;
  q.clip = true;
  q.clip_bottom_d = std::isinf(lo) ? (p.clip ? p.clip_bottom_d : -p.inlet_length_d)
                                   : (out.bed.size() > 0 ? lowest - pad : lo) / d;
  q.clip_top_d = std::isinf(hi) ? (p.clip ? p.clip_top_d : bed_height(bed) / d + p.outlet_length_d)
                                : (out.bed.size() > 0 ? highest + pad : hi) / d;
  q.wall_rings_d = std::move(rings_d);
  // Planes of its own cut nothing; only the scene's own plane (an infinite side) may need a cut.
  if (!std::isinf(lo) && !std::isinf(hi)) q.cut_at_clip_planes = false;
  return out;
}

CutWindow survey_window(const Bed& bed, const SurfaceParams& p, double lo, double hi) {
  SurfaceParams unringed = p;
  unringed.ring_wall_gap_m = std::numeric_limits<double>::infinity();
  return window_for_cuts(bed, unringed, lo, hi, {});
}

std::string in_bed_numbers(const CutWindow& window, const std::string& message) {
  static const std::regex named(R"((sphere|particle) (\d+))");
  std::string out;
  auto last = message.cbegin();
  for (std::sregex_iterator it(message.begin(), message.end(), named), end; it != end; ++it) {
    const std::size_t k = std::stoul((*it)[2].str());
    out.append(last, (*it)[0].first);
    out += (*it)[1].str() + " " + std::to_string(k < window.numbers.size() ? window.numbers[k] : k);
    last = (*it)[0].second;
  }
  out.append(last, message.cend());
  return out;
}

double opening_reach(const Bed& bed, const SurfaceParams& p) {
  return p.clip_clearance_d * reference_diameter(bed) + (1.0 - p.shrink_factor) * largest_diameter(bed);
}

void refuse_treatments_across_periodic_planes(const SurfaceParams& p) {
  using Treatment = SurfaceParams::Treatment;
  for (auto [t, key] : {std::pair{p.treatment, "contacts.treatment"}, std::pair{p.wall_treatment, "contacts.wall_treatment"}})
    if (t == Treatment::enlarge && !p.cut_at_periodic_planes)
      throw InputError(fmt::format("{} = \"enlarge\" on a periodic section (container.period_z) with "
                                   "contacts.at_periodic_planes = \"open\": the contacts a periodic plane crosses "
                                   "are opened by shrinking their spheres, which their enlarged neighbours would "
                                   "still overlap; allowed: contacts.at_periodic_planes = \"cut\", or \"bridge\", "
                                   "\"cap\", \"shrink\" or \"none\" (or no surface: outputs without \"stl\", "
                                   "\"mesh\" and \"case\")",
                                   key));
}

bool opens_contacts_at_periodic_planes(const SurfaceParams& p) {
  using Treatment = SurfaceParams::Treatment;
  auto treated = [](Treatment t) { return t == Treatment::bridge || t == Treatment::cap; };
  return treated(p.treatment) || treated(p.wall_treatment);
}

UnwrappedSection unwrap_periodic_section(const Bed& bed, const SurfaceParams& p, const std::vector<double>& keep_clear) {
  using Treatment = SurfaceParams::Treatment;
  if (bed.size() > 0) refuse_treatments_across_periodic_planes(p);
  const double H = bed.container->axial_period(), d = reference_diameter(bed);
  const double scale = p.treatment == Treatment::shrink ? p.shrink_factor : 1.0;
  auto radius = [&](std::size_t i) { return 0.5 * scale * bed.diameters[i]; };
  // Candidate heights: the middles of the intervals between the spheres' ends over one period
  // (round it), the 64 widest; where contacts may be opened at the planes, the ends at the
  // shrunk radius too, so that a sphere crosses a plane at either radius or at neither.
  const bool opens = opens_contacts_at_periodic_planes(p);
  std::vector<double> ends;
  for (std::size_t i = 0; i < bed.size(); ++i)
    for (double r : {radius(i), opens ? 0.5 * p.shrink_factor * bed.diameters[i] : radius(i)})
      for (double e : {bed.centres[i].z() - r, bed.centres[i].z() + r}) ends.push_back(e - H * std::floor(e / H));
  // The 64 widest intervals between `ends` (heights over one period, sorted here), widest first.
  auto widest = [H](std::vector<double> ends) {
    std::sort(ends.begin(), ends.end());
    std::vector<std::pair<double, double>> candidates;  // clearance, height
    for (std::size_t k = 0; k < ends.size(); ++k) {
      const double next = k + 1 < ends.size() ? ends[k + 1] : ends.front() + H;
      const double z = 0.5 * (ends[k] + next);
      candidates.push_back({0.5 * (next - ends[k]), z >= H ? z - H : z});
    }
    if (candidates.empty()) candidates.push_back({0.5 * H, 0.0});
    std::sort(candidates.begin(), candidates.end(), std::greater<>());
    candidates.resize(std::min<std::size_t>(candidates.size(), 64));
    return candidates;
  };
  std::vector<std::pair<double, double>> candidates = widest(ends);
  // For a cut through the contacts, of the 64 heights widest apart from `keep_clear` and the ends
  // alike, the first whose ends keep clip_clearance_d: the plane then meets no rim or end nearly
  // tangent where it can help it, and the circles' gaps on it are the treatment's, not narrow.
  if (!keep_clear.empty()) {
    std::vector<double> all = ends;
    for (double z : keep_clear) all.push_back(z - H * std::floor(z / H));
    auto end_clearance = [&](double z) {
      double c = HUGE_VAL;
      for (double e : ends) c = std::min({c, std::abs(z - e), H - std::abs(z - e)});
      return c;
    };
    for (const std::pair<double, double>& clearest : widest(all))
      if (const double c = end_clearance(clearest.second); c >= p.clip_clearance_d * d) {
        candidates = {{c, clearest.second}};
        break;
      }
  }
  if (!(candidates.front().first >= p.clip_clearance_d * d))
    throw InputError(fmt::format("surface.clip_clearance_d = {}: no height of the periodic section lies that clear of "
                                 "every sphere's top and bottom (at best {:.3g} d); allowed: a smaller clearance",
                                 p.clip_clearance_d, candidates.front().first / d));
  // Of those clear enough, the one whose cut circles keep widest apart from each other and from
  // the walls: the triangles of the periodic faces in those gaps are as narrow as they are.
  auto narrowest_gap = [&](double z) {
    std::vector<std::pair<Eigen::Vector3d, double>> circles;
    for (std::size_t i = 0; i < bed.size(); ++i) {
      double dz = bed.centres[i].z() - z;
      dz -= H * std::nearbyint(dz / H);
      if (std::abs(dz) < radius(i))
        circles.push_back({{bed.centres[i].x(), bed.centres[i].y(), z}, std::sqrt(radius(i) * radius(i) - dz * dz)});
    }
    double gap = HUGE_VAL;
    for (std::size_t a = 0; a < circles.size(); ++a) {
      // The wall gap of a circle is its sphere's, grown by d, less what that overlaps the wall.
      WallContact w[Container::kMaxWallContacts];
      const int nw = bed.container->wall_contacts(circles[a].first, circles[a].second + d, w);
      for (int k = 0; k < nw; ++k) gap = std::min(gap, d - w[k].overlap);
      for (std::size_t b = a + 1; b < circles.size(); ++b)
        gap = std::min(gap, (circles[a].first - circles[b].first).norm() - circles[a].second - circles[b].second);
    }
    return gap;
  };
  double z0 = candidates.front().second, best = -HUGE_VAL;
  UnwrappedSection out;
  out.clearance = candidates.front().first;
  for (const auto& [clearance, z] : candidates) {
    if (clearance < p.clip_clearance_d * d) break;
    if (const double g = narrowest_gap(z); g > best) best = g, z0 = z, out.clearance = clearance;
  }
  out.narrowest_gap = best;
  const double z1 = z0 + H;
  out.planes = {z0, z1, true};
  std::unique_ptr<Container> plain = bed.container->scaled(1.0);
  plain->set_axial_period(0.0);
  out.bed.container = std::move(plain);
  out.bed.reference_diameter_m = reference_diameter(bed);
  for (std::size_t i = 0; i < bed.size(); ++i) {
    Eigen::Vector3d c = bed.centres[i];
    if (c.z() < z0) c.z() += H;
    out.bed.centres.push_back(c);
    out.bed.diameters.push_back(bed.diameters[i]);
  }
  const std::size_t n = bed.size();
  out.twin.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d c = out.bed.centres[i];
    const bool below = c.z() - radius(i) < z0, above = c.z() + radius(i) > z1;
    if (!below && !above) continue;
    const int copy = static_cast<int>(out.bed.centres.size());
    out.bed.centres.push_back(c + Eigen::Vector3d(0.0, 0.0, above ? -H : H));
    out.bed.diameters.push_back(bed.diameters[i]);
    out.twin.push_back(below ? static_cast<int>(i) : -1);  // the copy crosses the upper plane
    if (above) out.twin[i] = copy;
  }
  return out;
}

}  // namespace bedforge::meshing
