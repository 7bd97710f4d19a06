#include "meshing/surface/periodic_cut.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/contacts.hpp"
#include "meshing/surface/plane_cut.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/spaced_points.hpp"
#include "meshing/surface/stl_io.hpp"
#include "meshing/surface/surface_checks.hpp"

namespace bedforge::meshing {

namespace {

// The spheres of `bed` (periodic along z, period H) repeated a period apart wherever a centre
// falls within [lo, hi] (m), in a copy of its container without the period.
Bed repeated(const Bed& bed, double lo, double hi) {
  const double H = bed.container->axial_period();
  Bed out;
  std::unique_ptr<Container> plain = bed.container->scaled(1.0);
  plain->set_axial_period(0.0);
  out.container = std::move(plain);
  out.reference_diameter_m = reference_diameter(bed);
  for (long k = static_cast<long>(std::floor(lo / H)) - 1; k * H <= hi + H; ++k)
    for (std::size_t i = 0; i < bed.size(); ++i) {
      const Eigen::Vector3d c = bed.centres[i] + Eigen::Vector3d(0.0, 0.0, static_cast<double>(k) * H);
      if (c.z() >= lo && c.z() <= hi) out.centres.push_back(c), out.diameters.push_back(bed.diameters[i]);
    }
  return out;
}

// The treated solid of one period, as treat_contacts reports it for a bed: that of two periods
// of the bed repeated less that of one, so that each contact (those across the period's ends
// too) counts once.
nlohmann::json one_period_treatment(const Bed& bed, const SurfaceParams& p) {
  const double H = bed.container->axial_period(), inf = std::numeric_limits<double>::infinity();
  auto treated = [&](int periods) {
    return treat_contacts(repeated(bed, 0.0, std::nextafter(periods * H, 0.0)), p, {-inf, inf, false}).report;
  };
  const nlohmann::json one = treated(1), two = treated(2);
  nlohmann::json out = two;
  for (const char* key : {"/contacts_treated/particle_particle", "/contacts_treated/particle_wall",
                          "/contacts_treated/by_kind/bridge", "/contacts_treated/by_kind/cap",
                          "/contacts_treated/by_kind/union"}) {
    const nlohmann::json::json_pointer at(key);
    out[at] = two[at].get<long>() - one[at].get<long>();
  }
  for (const char* key : {"/solid_volume_change_m3", "/solid_volume_exact_m3"}) {
    const nlohmann::json::json_pointer at(key);
    out[at] = two[at].get<double>() - one[at].get<double>();
  }
  const double solid = out["solid_volume_exact_m3"].get<double>(), change = out["solid_volume_change_m3"].get<double>();
  out["solid_volume_change_relative"] = change / (solid - change);
  return out;
}

// How far below each plane the two parts of the section meet at the least (m): beyond the
// cut's changes.
double seam_depth(const SurfaceParams& p, double d) {
  return std::max(kSeamDepthEdges * p.edge_length_d, kSeamDepthMinD) * d;
}

// The seam's depths below z0 (m) to try, best first: the least from seam_depth(p, d) up to H
// less that whose height, a period on or back, keeps kSymmetryClearanceD clear of every height
// where the treated `section` (one period from z0) has a mesh symmetric about it (a sphere's
// centre, a contact's point between two spheres): a triangle centred on the seam would be taken
// by both parts or by neither (a simple cubic array's spheres lie at such heights). Then, up to
// kSeamTries in all, the next such depths at least kSeamSpacingEdges edges from those before: a
// cap's regular rings can still take other diagonals in the two copies of a sphere that a seam
// crosses (docs/findings.md, 2026-12-03 and 2026-12-05), and a seam elsewhere passes other
// spheres. InputError when none is clear.
inline constexpr double kSymmetryClearanceD = 1e-4, kSeamSpacingEdges = 2.0;
inline constexpr int kSeamTries = 3;
std::vector<double> seam_depths_clear(const UnwrappedSection& section, const SurfaceParams& p, double d) {
  const double H = section.planes.z1 - section.planes.z0, z0 = section.planes.z0, least = seam_depth(p, d);
  const Bed& b = section.bed;
  // The heights less z0 that the seam keeps clear of, a period on and back.
  std::vector<std::pair<double, double>> taken;
  const double clearance = kSymmetryClearanceD * d;
  auto take = [&](double z) {
    for (double shift : {-H, 0.0, H}) taken.emplace_back(z - z0 - clearance + shift, z - z0 + clearance + shift);
  };
  const double joined = std::max({p.bridge_gap_d, p.cap_gap_d, p.enlarge_join_gap_d}) * d, reach = 2.0 * largest_diameter(b);
  std::vector<std::size_t> by_z(b.size());
  std::iota(by_z.begin(), by_z.end(), 0);
  std::sort(by_z.begin(), by_z.end(), [&b](std::size_t u, std::size_t v) { return b.centres[u].z() < b.centres[v].z(); });
  for (std::size_t k = 0; k < by_z.size(); ++k) {
    const std::size_t i = by_z[k];
    const double ri = 0.5 * b.diameters[i];
    take(b.centres[i].z());
    for (std::size_t l = k + 1; l < by_z.size(); ++l) {
      const std::size_t j = by_z[l];
      const double rj = 0.5 * b.diameters[j];
      if (b.centres[j].z() - b.centres[i].z() > reach) break;
      if ((b.centres[j] - b.centres[i]).norm() > ri + rj + joined) continue;
      const double at = (b.centres[i].z() * rj + b.centres[j].z() * ri) / (ri + rj);
      take(at);
    }
  }
  // The seam at z0 - m lies at t = H - m of the period: the highest free t in [least, H - least].
  auto clear = [&](double t) {
    return std::none_of(taken.begin(), taken.end(), [t](const auto& r) { return t > r.first && t < r.second; });
  };
  std::vector<double> clear_heights;
  if (clear(H - least)) clear_heights.push_back(H - least);
  for (const auto& [lo, hi] : taken)
    if (lo <= H - least && lo >= least && clear(lo)) clear_heights.push_back(lo);
  std::sort(clear_heights.begin(), clear_heights.end(), std::greater<>());
  if (clear_heights.empty())
    throw InputError(fmt::format(
        "contacts.at_periodic_planes = \"cut\": no height of the period {:.4g} d keeps clear of the spheres' centres "
        "and contacts, where its two parts would meet; allowed: \"open\"",
        H / d));
  std::vector<double> depths;
  for (const double t : clear_heights)
    if (static_cast<int>(depths.size()) < kSeamTries &&
        std::all_of(depths.begin(), depths.end(),
                    [&](double m) { return std::abs(H - m - t) >= kSeamSpacingEdges * p.edge_length_d * d; }))
      depths.push_back(H - t);
  return depths;
}

}  // namespace

void check_periodic_cut(const Container& container, const SurfaceParams& p, double d) {
  const double H = container.axial_period(), m = seam_depth(p, d);
  if (!(H >= 2.0 * m))
    throw InputError(fmt::format(
        "container.period_z_d = {:.4g} with contacts.at_periodic_planes = \"cut\": the section is joined {:.3g} d "
        "below each plane ({} edges of surface.edge_length_d = {}, at least {} d) and needs a period of twice that; "
        "allowed: a period of at least {:.3g} d, a shorter surface edge, or \"open\"",
        H / d, m / d, kSeamDepthEdges, p.edge_length_d, kSeamDepthMinD, 2.0 * m / d));
}

bool cuts_contacts_at_periodic_planes(const Bed& bed, const SurfaceParams& p) {
  using Treatment = SurfaceParams::Treatment;
  const bool joins = opens_contacts_at_periodic_planes(p) || p.treatment == Treatment::enlarge;
  return p.cut_at_periodic_planes && bed.container->axial_period() > 0.0 && joins;
}

namespace {

// build_cut_periodic_surface's section of `bed` between z0 and z0 + H (`section` as unwrapped),
// its two parts joined at the seam m below each plane; nullopt, with what did not match in
// `unmatched`, when the layout's surface does not repeat itself at that seam.
std::optional<FluidSurface> section_joined_at(const Bed& bed, const SurfaceParams& p, const UnwrappedSection& section,
                                              double z0, double m, std::string& unmatched) {
  const double H = bed.container->axial_period(), d = reference_diameter(bed), z1 = z0 + H, s = z0 - m;

  // 2. The bed repeated a period apart, whole spheres from piece_margin_d below the lower seam
  // to as far above the upper plane, in a window whose own planes cut nothing (window_for_cuts),
  // its walls ringed at the seams and the planes (a box's sides meshed in strips between them).
  const double margin = piece_margin_d(bed, p) * d;
  const Bed laid = repeated(bed, s - margin, z1 + margin);
  const CutWindow window = window_for_cuts(laid, p, s - margin, z1 + margin, {s / d, z0 / d, (s + H) / d, z1 / d});
  FluidSurface whole = build_fluid_surface(window.bed, window.surface);

  // 3. Cut at the lower plane: the fluid above it and below it, one face between them.
  PlaneCut cut = [&] {
    try {
      return cut_by_plane(whole.fluid, z0, plane_cut_params(p, window.bed, whole));
    } catch (const CutConflict& e) {
      throw InputError(fmt::format("the periodic section's lower plane: {}; allowed: a shorter "
                                   "surface.contact_edge_length_d or another treatment",
                                   e.what()));
    }
  }();
  whole.fluid = TriangleMesh();
  const TriangleMesh& above = cut.above;
  const TriangleMesh& below = cut.below;
  auto centroid_z = [](const TriangleMesh& t, std::size_t k) {
    return (t.points[t.triangles[k][0]].z() + t.points[t.triangles[k][1]].z() + t.points[t.triangles[k][2]].z()) / 3.0;
  };

  // 4. The section: the triangles above z0 below the upper seam, and those below z0 above the
  // lower seam moved up a period. Vertices of the part moved up keep their doubles plus H; the
  // upper seam's vertices of the part above take them (the same points, up to the rounding of
  // the layout's own repeat, checked below).
  FluidSurface out;
  TriangleMesh& f = out.fluid;
  std::vector<int> from_above(above.points.size(), -1);
  auto add_point = [&f](const Eigen::Vector3d& x) {
    f.points.push_back(x);
    return static_cast<int>(f.points.size()) - 1;
  };
  std::vector<char> kept(above.triangles.size(), 0);
  for (std::size_t t = 0; t < above.triangles.size(); ++t) {
    if (!(centroid_z(above, t) < s + H)) continue;
    kept[t] = 1;
    std::array<int, 3> tri;
    for (int k = 0; k < 3; ++k) {
      int& v = from_above[above.triangles[t][k]];
      if (v < 0) v = add_point(above.points[above.triangles[t][k]]);
      tri[k] = v;
    }
    f.triangles.push_back(tri);
    f.patch.push_back(f.patch_index(above.patches[above.patch[t]]));
  }
  // The upper seam's vertices: those of kept triangles that a dropped one shares, found by their
  // point a period down among the part below's.
  std::vector<char> on_seam(above.points.size(), 0);
  for (std::size_t t = 0; t < above.triangles.size(); ++t)
    if (!kept[t])
      for (int v : above.triangles[t])
        if (from_above[v] >= 0) on_seam[v] = 1;
  const double tolerance = 1e-7 * d;
  PointsByCell seam_grid(1e3 * tolerance);
  std::vector<int> seam_vertex;  // index in `above`
  for (std::size_t v = 0; v < above.points.size(); ++v)
    if (on_seam[v]) {
      seam_grid.add(above.points[v] - Eigen::Vector3d(0.0, 0.0, H), static_cast<int>(seam_vertex.size()));
      seam_vertex.push_back(static_cast<int>(v));
    }
  std::vector<int> from_below(below.points.size(), -1);
  const int outlet = f.patch_index("outlet");
  for (std::size_t t = 0; t < below.triangles.size(); ++t) {
    if (!(centroid_z(below, t) > s)) continue;
    std::array<int, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const int b = below.triangles[t][k];
      int& v = from_below[b];
      if (v < 0) {
        const Eigen::Vector3d x = below.points[b];
        int twin = -1;
        seam_grid.near(x, [&](int i) {
          if ((above.points[seam_vertex[i]] - Eigen::Vector3d(0.0, 0.0, H) - x).norm() < tolerance) twin = seam_vertex[i];
        });
        const Eigen::Vector3d up(x.x(), x.y(), x.z() + H);
        if (twin >= 0)
          v = from_above[twin], f.points[v] = up;
        else
          v = add_point(up);
      }
      tri[k] = v;
    }
    f.triangles.push_back(tri);
    const std::string& name = below.patches[below.patch[t]];
    f.patch.push_back(name == "outlet" ? outlet : f.patch_index(name));
  }

  // 5. The seam closed (its topology alone; the surface stage's own check follows).
  if (const SurfaceCheck closed = check_surface(f, SelfIntersectionTest::skip); !closed.closed || !closed.manifold) {
    unmatched = fmt::format("at the seam {:.4f} d below the planes {} edges unmatched, first at{}", m / d,
                            closed.defects.size(), describe_defects(closed));
    return std::nullopt;
  }

  // 6. What the surface stage reports of it.
  out.report = whole.report;
  for (const char* key : {"clip", "domain_m", "triangles", "min_angle_deg", "min_edge_d", "max_edge_d"})
    out.report.erase(key);
  nlohmann::json period = one_period_treatment(bed, p);
  for (auto& [key, value] : period.items()) out.report[key] = value;
  const double domain = bed.container->cross_section_area() * H;
  out.exact_volume_m3 = domain - out.report["solid_volume_exact_m3"].get<double>();
  out.report["fluid_volume_exact_m3"] = out.exact_volume_m3;
  out.report["void_fraction_bed_section_change"] = -out.report["solid_volume_change_m3"].get<double>() / domain;
  out.report["domain_m"] = {{"inlet_z", z0}, {"outlet_z", z1}};
  out.report["periodic_planes_m"] = {{"lower", z0},
                                     {"upper", z1},
                                     {"clearance_d", section.clearance / d},
                                     {"narrowest_gap_d", section.narrowest_gap / d},
                                     {"contacts_opened", 0},
                                     {"seam_depth_d", m / d},
                                     {"cut", to_json(cut)}};
  finish_cut_surface(out, d);
  return out;
}

}  // namespace

FluidSurface build_cut_periodic_surface(const Bed& bed, const SurfaceParams& p) {
  const double H = bed.container->axial_period(), d = reference_diameter(bed);
  check_periodic_cut(*bed.container, p, d);
  // 1. The planes: z0 the height widest apart from the contacts' rims and the spheres' ends
  // that keeps clip_clearance_d from the ends, a height the STL keeps as it is; the seam m below
  // each, at the next depth clear when the first does not join.
  const UnwrappedSection section = unwrap_periodic_section(
      bed, p, treated_heights(repeated(bed, -largest_diameter(bed), H + largest_diameter(bed)), p));
  const double z0 = round_to_ascii_stl(section.planes.z0);
  std::vector<std::string> tried;
  for (const double m : seam_depths_clear(section, p, d)) {
    std::string unmatched;
    if (std::optional<FluidSurface> out = section_joined_at(bed, p, section, z0, m, unmatched)) return std::move(*out);
    tried.push_back(unmatched);
  }
  throw std::runtime_error(fmt::format(
      "periodic section: the bed repeated a period on does not repeat its surface at any seam tried ({}); please "
      "report it with the bed",
      fmt::join(tried, "; ")));
}

}  // namespace bedforge::meshing
