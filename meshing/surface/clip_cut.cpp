#include "meshing/surface/clip_cut.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/contacts.hpp"
#include "meshing/surface/plane_cut.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/stl_io.hpp"

namespace bedforge::meshing {

bool cuts_contacts_at_clip_planes(const SurfaceParams& p) {
  using Treatment = SurfaceParams::Treatment;
  const auto joins = [](Treatment t) { return t == Treatment::bridge || t == Treatment::cap || t == Treatment::enlarge; };
  return p.clip && p.cut_at_clip_planes && (joins(p.treatment) || joins(p.wall_treatment));
}

FluidSurface build_cut_clip_surface(const Bed& bed, const SurfaceParams& p) {
  const double d = reference_diameter(bed), nan = std::numeric_limits<double>::quiet_NaN();
  // 1. The planes: each at the widest gap between the spheres' ends and the contacts' rims near
  // where it was asked, a height an ASCII STL keeps.
  const ClearHeights clear = plane_clear_heights_d(bed, p, true);
  auto placed = [&](double asked_d) {
    return round_to_ascii_stl(widest_interval_middle(clear, asked_d, p.clip_shift_d, nan, p.clip_clearance_d) * d);
  };
  const double lo = placed(p.clip_bottom_d), hi = placed(p.clip_top_d);
  if (!(hi > lo))
    throw InputError(fmt::format("surface.clip_window_d = [{}, {}]: its planes, moved clear of the spheres' ends and "
                                 "contacts, leave no window ({:.4g} to {:.4g} d); allowed: a taller window",
                                 p.clip_bottom_d, p.clip_top_d, lo / d, hi / d));

  // 2. The spheres within piece_margin_d of the window, whole, their walls ringed at the planes
  // (and where `p` rings them: a slab of a window in pieces, cut again at its planes), its own
  // planes half a diameter beyond the spheres' ends (and beyond the window's), cutting nothing.
  SurfaceParams plain = p;
  plain.cut_at_clip_planes = false;
  const double margin = piece_margin_d(bed, p) * d, pad = 0.5 * largest_diameter(bed);
  std::vector<double> rings = p.wall_rings_d;
  rings.insert(rings.end(), {lo / d, hi / d});
  CutWindow window = window_for_cuts(bed, plain, lo - margin, hi + margin, std::move(rings));
  SurfaceParams& q = window.surface;
  q.clip_bottom_d = std::min(q.clip_bottom_d, (lo - pad) / d);
  q.clip_top_d = std::max(q.clip_top_d, (hi + pad) / d);
  FluidSurface whole = [&] {
    try {
      return build_fluid_surface(window.bed, q);
    } catch (const InputError& e) {
      throw InputError(in_bed_numbers(window, e.what()));
    }
  }();

  // 3. Cut at the lower plane, keeping what lies above, then at the upper, keeping what lies below.
  const PlaneCutParams cut_params = plane_cut_params(p, window.bed, whole);
  nlohmann::json clip;
  TriangleMesh fluid = std::move(whole.fluid);
  for (const auto& [z, lower, asked] : {std::tuple{lo, true, p.clip_bottom_d}, std::tuple{hi, false, p.clip_top_d}}) {
    try {
      PlaneCut c = cut_by_plane(fluid, z, cut_params);
      fluid = std::move(lower ? c.above : c.below);
      clip[lower ? "inlet" : "outlet"] = {{"asked_d", asked}, {"used_d", z / d}, {"contacts_opened", 0}, {"cut", to_json(c)}};
    } catch (const CutConflict& e) {
      throw InputError(fmt::format("surface.clip_window_d = [{}, {}] with contacts.at_clip_planes = \"cut\": the {} "
                                   "plane at {:.4f} d: {}; allowed: another window, a shorter "
                                   "surface.contact_edge_length_d, or \"open\"",
                                   p.clip_bottom_d, p.clip_top_d, lower ? "lower" : "upper", z / d,
                                   in_bed_numbers(window, e.what())));
    }
  }

  // 4. What the surface stage reports of it: the solid and the contacts between the planes.
  const TreatedBed between = treat_contacts_measured_between(window.bed, q, lo, hi);
  FluidSurface out;
  out.fluid = std::move(fluid);
  // A slab of this window is cut again at its pieces' planes (its wall rings): that face must be
  // graded about the same ends, and sized from the same spheres, as the neighbouring slab's, whose
  // window is no clip window.
  out.ends_near_planes = std::move(whole.ends_near_planes);
  out.spheres_near_planes = std::move(whole.spheres_near_planes);
  out.report = whole.report;
  for (const char* key : {"clip", "domain_m", "opened_at_clip_planes"}) out.report.erase(key);
  out.report["parameters"] = to_json(p);
  out.report["contacts_treated"] = between.report["contacts_treated_between"];
  const double solid = between.solid_volume_between_m3, change = solid - between.untreated_volume_between_m3;
  const double domain = bed.container->cross_section_area() * (hi - lo);
  out.exact_volume_m3 = domain - solid;
  out.report["solid_volume_exact_m3"] = solid;
  out.report["solid_volume_change_m3"] = change;
  out.report["solid_volume_change_relative"] = change / between.untreated_volume_between_m3;
  out.report["fluid_volume_exact_m3"] = out.exact_volume_m3;
  out.report["void_fraction_bed_section_change"] = -change / domain;
  out.report["domain_m"] = {{"inlet_z", lo}, {"outlet_z", hi}};
  out.report["clip"] = std::move(clip);
  finish_cut_surface(out, d);
  return out;
}

}  // namespace bedforge::meshing
