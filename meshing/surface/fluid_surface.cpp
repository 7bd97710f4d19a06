#include "meshing/surface/fluid_surface.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <future>
#include <numbers>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/intersection_volumes.hpp"
#include "core/point_key.hpp"
#include "core/version.hpp"
#include "meshing/surface/defect_locations.hpp"
#include "meshing/surface/clip_cut.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/periodic_box.hpp"
#include "meshing/surface/periodic_cut.hpp"
#include "meshing/surface/contacts.hpp"
#include "meshing/surface/delaunay_walls.hpp"
#include "meshing/surface/gap_spacing.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/stl_io.hpp"
#include "meshing/surface/vtp_io.hpp"
#include "meshing/surface/wall_mesh.hpp"

namespace bedforge::meshing {

namespace {

constexpr std::array<const char*, 5> kTreatments{"none", "shrink", "enlarge", "bridge", "cap"};

SurfaceParams::Treatment treatment_of(const std::string& name) {
  return static_cast<SurfaceParams::Treatment>(std::find(kTreatments.begin(), kTreatments.end(), name) -
                                               kTreatments.begin());
}

}  // namespace

const char* treatment_name(SurfaceParams::Treatment t) { return kTreatments[static_cast<int>(t)]; }

SurfaceParams read_surface_params(SceneSection& c, SceneSection& s) {
  SurfaceParams p;
  p.treatment = treatment_of(c.choice("treatment", "bridge", {"none", "shrink", "enlarge", "bridge", "cap"}));
  const std::string wall = c.choice("wall_treatment", "same", {"same", "bridge", "cap", "none"});
  p.wall_treatment = wall == "same" ? p.treatment : treatment_of(wall);
  if (wall != "same" && (p.treatment == SurfaceParams::Treatment::shrink || p.treatment == SurfaceParams::Treatment::enlarge))
    throw InputError(fmt::format("contacts.wall_treatment = '{}' with contacts.treatment = '{}': shrink and enlarge act "
                                 "on the spheres, so on their wall contacts too; allowed: 'same', or a treatment "
                                 "bridge, cap or none",
                                 wall, treatment_name(p.treatment)));
  p.shrink_factor = c.number("shrink_factor", p.shrink_factor, Range{0.5, 1.0, false, true});
  p.enlarge_factor = c.number("enlarge_factor", p.enlarge_factor, Range{1.0, 1.2, true, false});
  p.enlarge_join_gap_d = c.number("enlarge_join_gap_d", p.enlarge_join_gap_d, Range::closed(0.0, 0.1));
  p.bridge_diameter_d = c.number("bridge_diameter_d", p.bridge_diameter_d, Range{0.0, 0.8, true, true});
  p.bridge_gap_d = c.number("bridge_gap_d", p.bridge_gap_d, Range{0.0, 0.5, false, false});
  p.cap_gap_d = c.number("cap_gap_d", p.cap_gap_d, Range{0.0, 0.2, true, false});
  p.cut_at_periodic_planes = c.choice("at_periodic_planes", "open", {"open", "cut"}) == "cut";
  p.cut_at_clip_planes = c.choice("at_clip_planes", "cut", {"open", "cut"}) == "cut";
  p.edge_length_d = s.number("edge_length_d", kSceneEdgeLengthD, Range{1e-3, 1.0, false, false});
  p.contact_edge_length_d = s.number("contact_edge_length_d", kSceneContactEdgeLengthD, Range{1e-3, 1.0, false, false});
  p.growth = s.number("growth", p.growth, Range{1.05, 2.0, false, false});
  p.facets_hold_sphere_volume = s.choice("sphere_facets", p.facets_hold_sphere_volume ? "volume" : "inscribed", {"inscribed", "volume"}) == "volume";
  p.cells_per_gap = s.number("cells_per_gap", kSceneCellsPerGap, Range::closed(0.0, 20.0));
  p.inlet_length_d = s.number("inlet_length_d", p.inlet_length_d, Range::non_negative());
  p.outlet_length_d = s.number("outlet_length_d", p.outlet_length_d, Range::non_negative());
  if (const std::vector<double> w = s.numbers("clip_window_d", Range::non_negative()); !w.empty()) {
    if (w.size() != 2 || !(w[1] > w[0]))
      throw InputError(fmt::format("surface.clip_window_d = [{}]: allowed: two heights above the floor in diameters, "
                                   "bottom below top, e.g. [2.0, 8.0]",
                                   fmt::join(w, ", ")));
    for (const char* k : {"inlet_length_d", "outlet_length_d"})
      if (s.has(k))
        throw InputError(fmt::format("surface.{} with surface.clip_window_d: a clipped domain begins and ends at the "
                                     "window's planes; allowed: one of the two",
                                     k));
    p.clip = true;
    p.clip_bottom_d = w[0];
    p.clip_top_d = w[1];
  }
  p.clip_shift_d = s.number("clip_shift_d", p.clip_shift_d, Range::closed(0.0, 1.0));
  p.clip_clearance_d = s.number("clip_clearance_d", p.clip_clearance_d, Range::closed(0.0, 0.1));
  p.min_angle_deg = s.number("min_angle_deg", p.min_angle_deg, Range::closed(0.0, 30.0));
  if (c.has("at_clip_planes") && p.cut_at_clip_planes && !p.clip)
    throw InputError("contacts.at_clip_planes = \"cut\" without surface.clip_window_d: there are no clip planes; "
                     "allowed: no contacts.at_clip_planes, or a clip window");
  return p;
}

int SurfaceParams::solid_change(bool periodic) const {
  auto sign = [](Treatment t) {
    return t == Treatment::bridge || t == Treatment::enlarge ? 1 : t == Treatment::none ? 0 : -1;
  };
  const int spheres = sign(treatment), walls = sign(wall_treatment);
  const int change = spheres == 0 ? walls : (walls == 0 || walls == spheres) ? spheres : 0;
  const bool opened = (periodic && !cut_at_periodic_planes) || (clip && !cut_at_clip_planes);
  return change > 0 && opened ? 0 : change;
}

nlohmann::json to_json(const SurfaceParams& p) {
  nlohmann::json j = {{"treatment", treatment_name(p.treatment)},
          {"wall_treatment", treatment_name(p.wall_treatment)},
          {"shrink_factor", p.shrink_factor},
          {"enlarge_factor", p.enlarge_factor},
          {"enlarge_join_gap_d", p.enlarge_join_gap_d},
          {"bridge_diameter_d", p.bridge_diameter_d},
          {"bridge_gap_d", p.bridge_gap_d},
          {"cap_gap_d", p.cap_gap_d},
          {"at_periodic_planes", p.cut_at_periodic_planes ? "cut" : "open"},
          {"at_clip_planes", p.cut_at_clip_planes ? "cut" : "open"},
          {"edge_length_d", p.edge_length_d},
          {"contact_edge_length_d", p.contact_edge_length_d},
          {"growth", p.growth},
          {"sphere_facets", p.facets_hold_sphere_volume ? "volume" : "inscribed"},
          {"cells_per_gap", p.cells_per_gap},
          {"inlet_length_d", p.inlet_length_d},
          {"outlet_length_d", p.outlet_length_d},
          {"clip_window_d", p.clip ? nlohmann::json::array({p.clip_bottom_d, p.clip_top_d}) : nlohmann::json(nullptr)},
          {"clip_shift_d", p.clip_shift_d},
          {"clip_clearance_d", p.clip_clearance_d},
          {"min_angle_deg", p.min_angle_deg}};
  if (!p.wall_rings_d.empty()) j["wall_rings_d"] = p.wall_rings_d;
  return j;
}

namespace {

// Points along the axis-aligned edge from corner a to corner b, about `edge` apart, b left out.
// Computed from the corners in one fixed order, so the faces that share an edge get
// bit-identical vertices and weld.
std::vector<Eigen::Vector3d> box_edge(Eigen::Vector3d a, Eigen::Vector3d b, double edge) {
  const bool flip = std::lexicographical_compare(b.data(), b.data() + 3, a.data(), a.data() + 3);
  if (flip) std::swap(a, b);
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / edge)));
  std::vector<Eigen::Vector3d> pts;
  for (int k = 0; k <= n; ++k) pts.push_back(k == n ? b : Eigen::Vector3d(a + (b - a) * (static_cast<double>(k) / n)));
  if (flip) std::reverse(pts.begin(), pts.end());
  pts.pop_back();
  return pts;
}

std::vector<Eigen::Vector3d> box_face_loop(const std::array<Eigen::Vector3d, 4>& corners, double edge) {
  std::vector<Eigen::Vector3d> loop;
  for (int k = 0; k < 4; ++k) {
    const auto side = box_edge(corners[k], corners[(k + 1) % 4], edge);
    loop.insert(loop.end(), side.begin(), side.end());
  }
  return loop;
}

// Whether a hole's loop meets the height z (m): has vertices on both sides of it, or two on it
// (snap_holes_to_rings can leave a loop's edge along a ring with the loop on one side).
bool meets(const WallHole& h, double z) {
  return (std::any_of(h.loop.begin(), h.loop.end(), [z](const auto& q) { return q.z() < z; }) &&
          std::any_of(h.loop.begin(), h.loop.end(), [z](const auto& q) { return q.z() > z; })) ||
         std::count_if(h.loop.begin(), h.loop.end(), [z](const auto& q) { return q.z() == z; }) >= 2;
}

// The spacing a side's strip grades to at `distance` (m) from hole `h`'s loop: the loop's,
// growing by `growth` per step away (spacing s then s g, ..., at distance about s + (g - 1) t).
double spacing_beside(const WallHole& h, double distance, double growth) {
  return h.spacing + (growth - 1.0) * distance;
}

// A box side's horizontal edge at a ring, from corner `from` to corner `to` (box_edge's points,
// `to` left out), passing each hole of `meeting` (loops that meet the ring only at vertices,
// snap_holes_to_rings) along its arc on the side `above` or below the ring (its edge along the
// ring where it lies on the other side): the strip's boundary there. Beside the holes of `near`
// (not meeting it), its points are as close as the strip's grading from their loops makes them
// (their spacing growing by `growth` per step away): a plane cut at the ring then meets a sphere
// that passes the side closely (above its union with the side) with as fine a row on both sides
// of the gap, not needles (docs/findings.md, 2026-12-05, session 81). Its points are decided on
// the coordinate along the edge alone, so that the strips on either side of the ring, and every
// ring a hole meets alike, take the same.
std::vector<Eigen::Vector3d> ring_path(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double edge,
                                       double growth, const std::vector<const WallHole*>& meeting,
                                       const std::vector<const WallHole*>& near, bool above) {
  const double z = from.z();
  const int axis = from.x() == to.x() ? 1 : 0;
  const std::vector<Eigen::Vector3d> row = box_edge(from, to, edge);
  const double step = std::abs(to[axis] - from[axis]) / static_cast<double>(row.size());
  const double sign = to[axis] > from[axis] ? 1.0 : -1.0;
  // Each hole's arc, from its ring vertex first met to the last, keyed by where it starts.
  std::vector<std::pair<double, std::vector<Eigen::Vector3d>>> arcs;
  std::vector<std::pair<double, double>> spans;
  for (const WallHole* h : meeting) {
    const auto& loop = h->loop;
    const std::size_t n = loop.size();
    std::size_t first = n, last = n;
    for (std::size_t k = 0; k < n; ++k)
      if (loop[k].z() == z) {
        if (first == n || sign * loop[k][axis] < sign * loop[first][axis]) first = k;
        if (last == n || sign * loop[k][axis] > sign * loop[last][axis]) last = k;
      }
    if (first == n || first == last)
      throw CutConflict(fmt::format("the hole of particle {} meets the ring at z = {} m but not at two vertices",
                                    h->particle, z));
    // Of the two ways round from `first` to `last`, the one on the side asked; where the loop
    // lies on the other side, its edge along the ring.
    std::vector<Eigen::Vector3d> chosen;
    for (const long dir : {1L, -1L}) {
      std::vector<Eigen::Vector3d> arc{loop[first]};
      bool on_side = true;
      for (std::size_t k = (first + n + dir) % n; k != last; k = (k + n + dir) % n) {
        arc.push_back(loop[k]);
        on_side = on_side && (above ? loop[k].z() >= z : loop[k].z() <= z);
      }
      arc.push_back(loop[last]);
      if (on_side && (chosen.empty() || arc.size() > chosen.size())) chosen = std::move(arc);
    }
    if (!chosen.empty()) arcs.emplace_back(sign * loop[first][axis], std::move(chosen));
    spans.emplace_back(std::min(loop[first][axis], loop[last][axis]), std::max(loop[first][axis], loop[last][axis]));
  }
  if (arcs.size() != meeting.size())
    throw CutConflict(fmt::format("a hole meeting the ring at z = {} m has no way round on one side of it", z));
  // The ring's points: the edge's, less those within a step of a hole's span, and between the
  // two, points graded by `growth` from the hole's spacing (a hole's vertex an edge from the next
  // ring point would make needles beside it).
  std::vector<double> along;
  for (std::size_t k = 0; k < row.size(); ++k) {
    const double x = row[k][axis];
    if (k == 0 || std::none_of(spans.begin(), spans.end(),
                               [&](const auto& sp) { return x > sp.first - step && x < sp.second + step; }))
      along.push_back(x);
  }
  // Both corners are kept off alike: the ring is walked from either end (once per strip beside
  // it), and only `from` is in the row.
  const double lo = std::min(from[axis], to[axis]), hi = std::max(from[axis], to[axis]);
  for (std::size_t h = 0; h < meeting.size(); ++h)
    for (const double out : {-1.0, 1.0}) {
      const double end = out < 0.0 ? spans[h].first : spans[h].second;
      double at = end, spacing = std::min(meeting[h]->spacing, step);
      while (true) {
        at += out * spacing;
        const bool clear = std::all_of(along.begin(), along.end(), [&](double x) { return std::abs(x - at) > 0.6 * spacing; }) &&
                           std::none_of(spans.begin(), spans.end(), [&](const auto& sp) {
                             return at > sp.first - 0.5 * spacing && at < sp.second + 0.5 * spacing;
                           });
        if (!clear || at <= lo + 0.6 * spacing || at >= hi - 0.6 * spacing) break;
        along.push_back(at);
        spacing = std::min(growth * spacing, step);
      }
    }
  // Intervals beside the holes near the ring halved until no longer than the grading there (to
  // a fifth), from both corners and in ascending order, so that either direction finds the same
  // points.
  if (!near.empty()) {
    const auto graded = [&](double x) {
      double spacing = step;
      for (const WallHole* h : near)
        for (const Eigen::Vector3d& q : h->loop)
          spacing = std::min(spacing, spacing_beside(*h, std::hypot(q[axis] - x, q.z() - z), growth));
      return spacing;
    };
    std::vector<double> ends = along;
    ends.push_back(to[axis]);
    std::sort(ends.begin(), ends.end());
    const std::function<void(double, double)> halve = [&](double u, double v) {
      const double mid = 0.5 * (u + v);
      if (v - u <= 1.2 * std::min({graded(u), graded(mid), graded(v)})) return;
      along.push_back(mid);
      halve(u, mid), halve(mid, v);
    };
    for (std::size_t k = 0; k + 1 < ends.size(); ++k)
      if (std::none_of(spans.begin(), spans.end(),
                       [&](const auto& sp) { return ends[k] < sp.second && ends[k + 1] > sp.first; }))
        halve(ends[k], ends[k + 1]);
  }
  std::sort(along.begin(), along.end(), [sign](double u, double v) { return sign * u < sign * v; });
  std::sort(arcs.begin(), arcs.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
  std::vector<Eigen::Vector3d> out;
  std::size_t next = 0;
  for (const double x : along) {
    for (; next < arcs.size() && arcs[next].first < sign * x; ++next)
      out.insert(out.end(), arcs[next].second.begin(), arcs[next].second.end());
    Eigen::Vector3d q = from;
    q[axis] = x;
    out.push_back(q);
  }
  for (; next < arcs.size(); ++next) out.insert(out.end(), arcs[next].second.begin(), arcs[next].second.end());
  return out;
}

}  // namespace

std::optional<GapSpacing> gap_spacing(const SurfaceParams& p, double d, const std::vector<Eigen::Vector3d>& centres,
                                      const std::vector<double>& radii, const std::vector<char>& kept,
                                      const Container& container) {
  if (p.cells_per_gap <= 0.0) return std::nullopt;
  const double edge = p.edge_length_d * d;
  return GapSpacing(centres, radii, kept, container, p.cells_per_gap, std::min(p.contact_edge_length_d * d, edge), edge);
}

std::optional<GapSpacing> facet_clearance(const SurfaceParams& p, double d, const std::vector<Eigen::Vector3d>& centres,
                                          const std::vector<double>& radii, const std::vector<char>& kept,
                                          const Container& container) {
  if (!p.facets_hold_sphere_volume) return std::nullopt;
  const double edge = p.edge_length_d * d;
  return GapSpacing(centres, radii, kept, container, 3.0, edge, edge);
}

namespace {

// The planes asked for below and above the fluid domain (m), before treat_contacts moves clip planes.
DomainPlanes asked_planes(const Bed& bed, const SurfaceParams& p) {
  const double d = reference_diameter(bed);
  if (p.clip) return {p.clip_bottom_d * d, p.clip_top_d * d, true};
  return {-p.inlet_length_d * d, bed_height(bed) + p.outlet_length_d * d, false};
}

// A flat face at the lower plane as the face at `z` above it, facing the other way, its
// triangles labelled `patch`: the same vertices in x and y, bit for bit.
WallMesh moved_up(const WallMesh& lower, double z, const std::string& patch) {
  WallMesh m = lower;
  for (TriangleMesh* t : {&m.outside, &m.inside}) {
    for (Eigen::Vector3d& q : t->points) q.z() = z;
    for (auto& tri : t->triangles) std::swap(tri[1], tri[2]);
    for (std::string& name : t->patches) name = patch;
  }
  return m;
}

// The bed as its surface is meshed, treated: a periodic section unwrapped between its planes
// a period apart (clip_planes.hpp), any other bed as it is (not copied).
struct LaidOut {
  std::optional<UnwrappedSection> section;
  TreatedBed treated;
  const Bed& given;
  const Bed& bed() const { return section ? section->bed : given; }
  bool periodic() const { return section.has_value(); }
};
LaidOut lay_out(const Bed& bed, const SurfaceParams& p) {
  if (bed.container->axial_period() > 0.0) {
    std::optional<UnwrappedSection> u = unwrap_periodic_section(bed, p);
    if (cuts_contacts_at_periodic_planes(bed, p)) {
      // Sized as cut through (build_cut_periodic_surface): every contact treated, a sphere that
      // crosses a plane and its copy a period away each counted within the planes.
      const double inf = std::numeric_limits<double>::infinity();
      TreatedBed tb = treat_contacts(u->bed, p, {-inf, inf, false});
      tb.planes = u->planes;
      return {std::move(u), std::move(tb), bed};
    }
    TreatedBed tb = treat_periodic_section(*u, p);
    return {std::move(u), std::move(tb), bed};
  }
  if (cuts_contacts_at_clip_planes(p)) {
    // Sized as cut through (build_cut_clip_surface): every contact treated, the solid between
    // the planes asked, the spheres beyond them left out.
    const DomainPlanes planes = asked_planes(bed, p);
    TreatedBed tb = treat_contacts_measured_between(bed, p, planes.z0, planes.z1);
    tb.solid_volume = tb.solid_volume_between_m3;
    tb.planes = planes;
    for (std::size_t i = 0; i < bed.size(); ++i)
      tb.kept[i] = bed.centres[i].z() + tb.radius[i] > planes.z0 && bed.centres[i].z() - tb.radius[i] < planes.z1;
    return {std::nullopt, std::move(tb), bed};
  }
  return {std::nullopt, treat_contacts(bed, p, asked_planes(bed, p)), bed};
}

}  // namespace

FluidDomainProfile fluid_domain_profile(const Bed& given, const SurfaceParams& p, double volume_per_cell, int bins,
                                        const std::optional<std::array<double, 2>>& grid) {
  const LaidOut laid = lay_out(given, p);
  const Bed& bed = laid.bed();
  const TreatedBed& tb = laid.treated;
  FluidDomainProfile out{{}, grid ? (*grid)[0] : tb.planes.z0, grid ? (*grid)[1] : tb.planes.z1, {}, {}, {}, {},
                         tb.bed_min_concave_wall_gap};
  out.size.volume_m3 = bed.container->cross_section_area() * (tb.planes.z1 - tb.planes.z0) - tb.solid_volume;
  const double d = reference_diameter(bed), edge = p.edge_length_d * d, height = (out.z1 - out.z0) / bins;
  const double per_volume = 1.0 / (edge * edge * edge);
  // The fluid: each bin's cross-section less the spheres' slices in it; and the surfaces' cells,
  // the walls' and the spheres' zones (2 pi r times the zone's height).
  const double per_area = kCellsPerSurfaceEdgeSquared / (edge * edge);
  out.cells.assign(bins, (bed.container->cross_section_area() * per_volume + bed.container->wall_perimeter() * per_area) * height);
  out.fluid_m3.assign(bins, bed.container->cross_section_area() * height);
  out.gap_cells.assign(bins, 0.0);
  for (std::size_t i = 0; i < bed.size(); ++i) {
    if (!tb.kept[i]) continue;
    const double r = tb.radius[i], zc = bed.centres[i].z();
    const int first = std::max(0, static_cast<int>((zc - r - out.z0) / height));
    const int last = std::min(bins - 1, static_cast<int>((zc + r - out.z0) / height));
    for (int b = first; b <= last; ++b) {
      const double lo = std::max(out.z0 + b * height, zc - r), hi = std::min(out.z0 + (b + 1) * height, zc + r);
      const double solid = sphere_slab_volume(r, zc, lo, hi);
      out.cells[b] += (2.0 * std::numbers::pi * r * std::max(0.0, hi - lo)) * per_area - solid * per_volume;
      out.fluid_m3[b] -= solid;
    }
  }
  // A loop's spacing is the contact edge (or less, on a short loop): graded from it up to `edge`,
  // in full up to a contact edge of half the edge, taken to fall linearly to none at the edge.
  // Each loop binned by its first point.
  out.loop_edges.assign(bins, 0.0);
  if (p.contact_edge_length_d < p.edge_length_d) {
    const double graded = 0.5 * (p.contact_edge_length_d + p.edge_length_d) * d;
    const double weight = std::min(2.0 * (1.0 - p.contact_edge_length_d / p.edge_length_d), 1.0);
    // A clip window cut through its contacts is sized from the whole bed's treatment: the loops
    // beyond its planes are left out.
    const bool beyond = cuts_contacts_at_clip_planes(p);
    auto add = [&](const auto& loop, double spacing) {
      if (!(spacing < graded) || loop.empty()) return;
      if (beyond && (loop.front().z() < tb.planes.z0 || loop.front().z() > tb.planes.z1)) return;
      const int b = std::clamp(static_cast<int>(std::floor((loop.front().z() - out.z0) / height)), 0, bins - 1);
      out.loop_edges[b] += weight * static_cast<double>(loop.size());
      out.size.contact_loop_edges += weight * static_cast<double>(loop.size());
    };
    for (std::size_t i = 0; i < bed.size(); ++i)
      if (tb.kept[i])
        for (const SphereCut& c : tb.cuts[i]) add(c.loop, c.spacing);
    for (const auto& holes : tb.wall_holes)
      for (const WallHole& h : holes) add(h.loop, h.spacing);
  }
  out.size.thin_gap_contacts = static_cast<double>(tb.thin_gap_contacts);
  const std::optional<GapSpacing> gaps = gap_spacing(p, d, bed.centres, tb.radius, tb.kept, *bed.container);
  if (gaps) {
    // The added cells go as one over the volume per cell (GapSpacing::added_cells_profile).
    const std::vector<double> added = gaps->added_cells_profile(1.0, out.z0, out.z1, bins);
    for (int b = 0; b < bins; ++b) {
      out.cells[b] += added[b], out.gap_cells[b] = added[b] / volume_per_cell;
      out.size.gap_cells += out.gap_cells[b];
    }
  }
  return out;
}

FluidSurface build_fluid_surface(const Bed& given, const SurfaceParams& p) {
  if (is_fully_periodic_box(*given.container)) return build_periodic_box_surface(given, p);
  if (cuts_contacts_at_periodic_planes(given, p)) return build_cut_periodic_surface(given, p);
  if (cuts_contacts_at_clip_planes(p)) return build_cut_clip_surface(given, p);
  const double top = bed_height(given);
  LaidOut laid = lay_out(given, p);
  const Bed& bed = laid.bed();
  TreatedBed& tb = laid.treated;
  const double d = reference_diameter(bed), edge = p.edge_length_d * d;
  const double z0 = tb.planes.z0, z1 = tb.planes.z1;
  const Container& c = *bed.container;
  const auto* ann = dynamic_cast<const Annulus*>(&c);
  const auto* cyl = dynamic_cast<const Cylinder*>(&c);
  const auto* box = dynamic_cast<const Box*>(&c);
  const double R = ann ? ann->outer_radius() : cyl ? cyl->radius() : 0.0;
  const double r_in = ann ? ann->inner_radius() : 0.0;

  // A curved wall is faceted between vertices on it: its facets lie inside it by up to the
  // sagitta, which must stay below half the narrowest wall gap or a facet would come close to a
  // sphere. Where the spheres' edge is too long for that, the curved walls (a few thousand
  // triangles; an annulus's two share the end rings' meshes) take the longest edge whose
  // sagitta is 0.4 of the gap, down to the contact edge.
  // With rings, the whole bed's gap: every window of the bed then rings its walls alike (a
  // window's own spheres and opened contacts differ; window_for_cuts).
  // Without rings, given the whole bed's (a slab made from the spheres near it): the narrower.
  const double wall_gap = !p.wall_rings_d.empty()    ? (p.ring_wall_gap_m > 0.0 ? p.ring_wall_gap_m : tb.bed_min_concave_wall_gap)
                          : p.ring_wall_gap_m > 0.0 ? std::min(tb.min_concave_wall_gap, p.ring_wall_gap_m)
                                                    : tb.min_concave_wall_gap;
  double wall_edge = edge;
  if (!box && ring_sagitta(R, edge) >= 0.5 * wall_gap) {
    wall_edge = wall_gap > 0.0 ? ring_edge_for_sagitta(R, 0.4 * wall_gap) : 0.0;
    if (!(wall_edge >= p.contact_edge_length_d * d))
      throw InputError(fmt::format(
          "surface.edge_length_d = {}: the wall facets would lie up to {:.3g} d inside the wall, more than half the "
          "narrowest gap left at the wall ({:.3g} d), and a wall edge short enough ({:.3g} d) is below "
          "surface.contact_edge_length_d = {}; allowed: a treatment that leaves a wider gap at the wall",
          p.edge_length_d, ring_sagitta(R, edge) / d, wall_gap / d, wall_edge / d,
          p.contact_edge_length_d));
  }
  const double wall_sag = box ? 0.0 : ring_sagitta(R, wall_edge);

  // Rings on the walls at the heights asked (those inside the window), each a height the STL's
  // rounding keeps: the holes' loops meet them at vertices, moved there alike in the loops' other
  // owners (a bridge's end, a sphere's cut); a box's sides are meshed in strips between them.
  std::vector<double> rings;
  if (!p.wall_rings_d.empty() && laid.periodic())
    throw std::invalid_argument("build_fluid_surface: wall rings on a periodic section (its copy laid out is not)");
  for (double h : p.wall_rings_d)
    if (const double z = round_to_ascii_stl(h * d); z > z0 + wall_edge && z < z1 - wall_edge) rings.push_back(z);
  std::sort(rings.begin(), rings.end());
  if (!rings.empty()) {
    std::unordered_map<PointKey, Eigen::Vector3d, PointKeyHash> moved;
    for (auto& holes : tb.wall_holes)
      for (const auto& [from, to] : snap_holes_to_rings(holes, rings)) moved.insert_or_assign(PointKey(from), to);
    auto follow = [&moved](Eigen::Vector3d& q) {
      if (const auto it = moved.find(PointKey(q)); it != moved.end()) q = it->second;
    };
    for (TriangleMesh& m : tb.parts)
      for (Eigen::Vector3d& q : m.points) follow(q);
    for (auto& cuts : tb.cuts)
      for (SphereCut& cut : cuts)
        for (Eigen::Vector3d& q : cut.loop) follow(q);
  }

  // Edges shortened where the surface faces another across a narrow gap, and graded about the
  // spheres' ends near the planes it is cut at (its rings) or ends at (a clip window's, a
  // periodic section's).
  const std::optional<GapSpacing> gaps = gap_spacing(p, d, bed.centres, tb.radius, tb.kept, c);
  const std::optional<GapSpacing> clearance = facet_clearance(p, d, bed.centres, tb.radius, tb.kept, c);
  // At the planes it ends at, sphere_mesh cuts the spheres along loops of their own spacing,
  // which seeds finer than it beside them would break: there only the ends not cut are graded.
  std::vector<EndNearPlane> ends = ends_near_planes(bed.centres, tb.radius, rings, edge);
  if (p.clip || laid.periodic())
    for (const EndNearPlane& e : ends_near_planes(bed.centres, tb.radius, {z0, z1}, edge))
      if (e.gap() > 0.0) ends.push_back(e);
  std::vector<std::vector<const EndNearPlane*>> ends_of(bed.size());
  for (const EndNearPlane& e : ends) ends_of[e.sphere].push_back(&e);
  std::vector<double> cut_planes = rings;
  if (p.clip || laid.periodic()) cut_planes.insert(cut_planes.end(), {z0, z1});
  std::vector<SphereNearPlane> near_cuts =
      gaps ? spheres_near_planes(bed.centres, tb.radius, cut_planes, kSpheresNearPlaneReach * p.cells_per_gap * edge) : std::vector<SphereNearPlane>{};
  auto field = [&](int self) {
    SpacingField f = gaps ? SpacingField{[&gaps, self](const Eigen::Vector3d& q) { return gaps->at(q, self); }, gaps->finest()}
                          : SpacingField{};
    if (self >= 0)
      for (const EndNearPlane* e : ends_of[self])
        for (const auto& seed : sphere_end_seeds(*e, edge)) f.seeds.push_back(seed);
    return f;
  };

  // Spheres, each on its own (in parallel), stopping at their cuts: meshed on other threads
  // while this one meshes the container, whose wall is one large piece.
  const std::size_t n = bed.size();
  std::vector<TriangleMesh> spheres(n);
  std::vector<double> chordal(n, 0.0), pushed(n, 0.0);
  std::vector<std::string> failure(n);
  std::future<void> spheres_meshed = std::async(std::launch::async, [&] {
#pragma omp parallel for schedule(dynamic, 16)
    for (std::size_t i = 0; i < n; ++i) {
      if (!tb.kept[i]) continue;
      try {
        spheres[i] = sphere_mesh(bed.centres[i], tb.radius[i], tb.cuts[i], edge, p.growth, true, "particles",
                                 field(static_cast<int>(i)));
        chordal[i] = chordal_deviation(spheres[i], bed.centres[i], tb.radius[i]);
        if (clearance)
          pushed[i] = match_sphere_volume(spheres[i], bed.centres[i], tb.radius[i], tb.cuts[i],
                                          [&clearance, i](const Eigen::Vector3d& x) { return clearance->gap(x, static_cast<int>(i)); });
      } catch (const CutConflict& e) {
        failure[i] = fmt::format("sphere {} (cuts: {}): {}; allowed: a shorter surface.contact_edge_length_d or "
                                 "another treatment",
                                 i, fmt::join(tb.cut_names[i], ", "), e.what());
      }
    }
  });

  // Container: walls with holes where the bed meets them, inlet and outlet sharing their edges
  // (with holes where spheres cross clip planes); what the holes cut out closes the bed solid.
  FluidSurface out;
  TriangleMesh& f = out.fluid;
  // The triangles appended since the last piece, as a piece of the self-intersection test.
  using Shape = SurfacePiece::Shape;
  auto piece = [&f, &out](Shape shape, const Eigen::Vector3d& centre = Eigen::Vector3d::Zero(), double radius = 0.0,
                          std::vector<std::pair<Eigen::Vector3d, double>> cut_planes = {}) {
    const std::size_t first = out.pieces.empty() ? 0 : out.pieces.back().last;
    if (f.triangles.size() <= first) return;
    SurfacePiece p;
    p.first = first, p.last = f.triangles.size(), p.shape = shape, p.centre = centre, p.radius = radius;
    p.cut_planes = std::move(cut_planes);
    out.pieces.push_back(std::move(p));
  };
  auto add = [&](const std::string& what, Shape shape, double radius, const std::function<WallMesh()>& mesh) {
    try {
      const WallMesh m = mesh();
      f.append(m.outside);
      piece(shape, Eigen::Vector3d::Zero(), radius);
      out.bed.append(m.inside);
    } catch (const CutConflict& e) {
      throw InputError(fmt::format("the {}: {}", what, e.what()));
    }
  };
  // The curved walls' end rows: on a periodic section, as fine as the wall beside them where
  // spheres cross the planes; else uniform (the structured rings of the inlet and outlet share
  // them, and two slabs' clip windows share a plane whose row must not depend on either's bed).
  auto row_parts_of = [&](double radius) {
    return !box && laid.periodic() ? end_row_parts(radius, ring_points(radius, wall_edge), z0, z1, field(-1))
                                   : std::vector<int>{};
  };
  const std::vector<int> row_parts = row_parts_of(R), inner_row_parts = ann ? row_parts_of(r_in) : std::vector<int>{};
  const double hx = box ? 0.5 * box->size_x() : 0.0, hy = box ? 0.5 * box->size_y() : 0.0;
  auto corner = [&](const Eigen::Vector2d& s, double z) { return Eigen::Vector3d(s.x() * hx, s.y() * hy, z); };
  if (box) {
    // Sides in the order of TreatedBed::wall_holes: normal out of the fluid (+w of the face's
    // frame) and the signs (x, y) of its two ends.
    const std::array<std::tuple<Eigen::Vector3d, Eigen::Vector2d, Eigen::Vector2d>, 4> sides{
        {{-Eigen::Vector3d::UnitX(), {-1, -1}, {-1, 1}},
         {Eigen::Vector3d::UnitX(), {1, -1}, {1, 1}},
         {-Eigen::Vector3d::UnitY(), {-1, -1}, {1, -1}},
         {Eigen::Vector3d::UnitY(), {-1, 1}, {1, 1}}}};
    // A side with rings is meshed strip by strip between them, so that its row of vertices at
    // a ring is the same at every ring of one bed (a periodic section's seams): the ring's points
    // and, where a hole meets it, the hole's vertices on it, each strip passing the hole along
    // its own side of the loop.
    std::vector<double> strips{z0};
    strips.insert(strips.end(), rings.begin(), rings.end());
    strips.push_back(z1);
    for (std::size_t k = 0; k < sides.size(); ++k) {
      const auto& [normal, a, b] = sides[k];
      const Frame frame = Frame::along(Eigen::Vector3d(normal.x() * hx, normal.y() * hy, 0.0), normal);
      // Per ring, the holes meeting it and those near it (within the reach of their grading);
      // per strip, the holes within it.
      std::vector<std::vector<const WallHole*>> meeting(strips.size()), near(strips.size());
      std::vector<std::vector<WallHole>> holes_of(strips.size() - 1);
      for (const WallHole& h : tb.wall_holes[k]) {
        std::vector<std::size_t> rings_met;
        for (std::size_t j = 1; j + 1 < strips.size(); ++j)
          if (meets(h, strips[j])) rings_met.push_back(j);
        if (rings_met.size() > 1)
          throw InputError(fmt::format("the box's side {}: the contact of particle {} meets two of its rings, {:.6g} "
                                       "and {:.6g} m; allowed: planes farther apart",
                                       k, h.particle, strips[rings_met[0]], strips[rings_met[1]]));
        if (!rings_met.empty()) {
          meeting[rings_met[0]].push_back(&h);
          continue;
        }
        for (std::size_t j = 1; j + 1 < strips.size(); ++j)
          if (std::any_of(h.loop.begin(), h.loop.end(), [&](const Eigen::Vector3d& q) {
                return spacing_beside(h, std::abs(q.z() - strips[j]), p.growth) < edge;
              }))
            near[j].push_back(&h);
        const auto [lowest, highest] =
            std::minmax_element(h.loop.begin(), h.loop.end(), [](const auto& u, const auto& v) { return u.z() < v.z(); });
        const double mid = 0.5 * (lowest->z() + highest->z());
        holes_of[std::upper_bound(strips.begin() + 1, strips.end() - 1, mid) - strips.begin() - 1].push_back(h);
      }
      for (std::size_t j = 0; j + 1 < strips.size(); ++j) {
        const double lo = strips[j], hi = strips[j + 1];
        std::vector<Eigen::Vector3d> loop =
            ring_path(corner(a, lo), corner(b, lo), edge, p.growth, meeting[j], near[j], true);
        for (const auto& part : {box_edge(corner(b, lo), corner(b, hi), edge),
                                 ring_path(corner(b, hi), corner(a, hi), edge, p.growth, meeting[j + 1], near[j + 1], false),
                                 box_edge(corner(a, hi), corner(a, lo), edge)})
          loop.insert(loop.end(), part.begin(), part.end());
        add("wall", Shape::plane, 0.0,
            [&] { return plane_mesh(frame, {loop}, edge, holes_of[j], p.growth, true, "wall", field(-1)); });
      }
    }
  } else {
    add("wall", Shape::cylinder, R, [&] {
      return wall_mesh(R, z0, z1, wall_edge, tb.wall_holes[0], p.growth, true, "wall", field(-1), rings, row_parts);
    });
    if (ann)
      add("inner_wall", Shape::cylinder, r_in, [&] {
        return wall_mesh(r_in, z0, z1, wall_edge, tb.wall_holes[1], p.growth, false, "inner_wall", field(-1), rings,
                         inner_row_parts);
      });
  }
  // Inlet and outlet: their edges are the walls' end rows (or the box's edges).
  using Loops = std::vector<std::vector<Eigen::Vector3d>>;
  auto end_boundary = [&](const Frame& frame, double z) {
    if (box) return Loops{box_face_loop({corner({-1, -1}, z), corner({1, -1}, z), corner({1, 1}, z), corner({-1, 1}, z)}, edge)};
    Loops boundary{end_row(frame, R, ring_points(R, wall_edge), row_parts).points};
    if (ann) boundary.push_back(end_row(frame, r_in, ring_points(r_in, wall_edge), inner_row_parts).points);
    return boundary;
  };
  WallMesh inlet;  // a periodic section's outlet is its copy a period up, so the two are cyclic patches
  for (auto [z, holes, patch, up] : {std::tuple{z0, &tb.inlet_holes, "inlet", false}, std::tuple{z1, &tb.outlet_holes, "outlet", true}}) {
    const Frame frame = Frame::along({0.0, 0.0, z}, Eigen::Vector3d::UnitZ());
    if (!box && !p.clip && !laid.periodic()) {  // nothing cuts it: the structured ring
      f.append(ring_mesh(frame, r_in, R, wall_edge, kBreakCocircular, up, patch));
      piece(Shape::plane);
      continue;
    }
    if (laid.periodic() && up) {
      add(patch, Shape::plane, 0.0, [&] { return moved_up(inlet, z1, patch); });
      continue;
    }
    // Graded about the ends near it; a periodic section's inlet also about those near its outlet,
    // which is the inlet moved up a period.
    std::vector<EndNearPlane> at = ends_at(ends, z, edge);
    if (laid.periodic())
      for (EndNearPlane e : ends_at(ends, z1, edge)) {
        e.plane_z = z0, e.centre.z() -= z1 - z0;
        at.push_back(e);
      }
    SpacingField seeded;
    seeded.seeds = plane_end_seeds(at, edge);
    add(patch, Shape::plane, 0.0, [&] {
      WallMesh m = plane_mesh(frame, end_boundary(frame, z), edge, *holes, p.growth, up, patch, seeded);
      if (laid.periodic()) inlet = m;
      return m;
    });
  }
  spheres_meshed.get();
  for (const auto& message : failure)
    if (!message.empty()) throw InputError(message);
  // The bed solid (normals out of it), and the same pieces turned inside out for the fluid;
  // each piece is released once appended (at N = 1e4 the pieces are gigabytes).
  std::size_t points = 0, triangles = 0;
  for (const auto* pieces : {&spheres, &tb.parts})
    for (const auto& m : *pieces) points += m.points.size(), triangles += m.triangles.size();
  f.reserve(points, triangles);
  out.bed.reserve(points, triangles);
  auto add_solid = [&](TriangleMesh& m) {
    out.bed.append(m);
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
    f.append(m);
    m = TriangleMesh();
  };
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::pair<Eigen::Vector3d, double>> cut_planes;
    for (const SphereCut& cut : tb.cuts[i]) {  // at the loop's farthest point along the axis (a curved wall's loop is not flat)
      double h = -HUGE_VAL;
      for (const auto& q : cut.loop) h = std::max(h, cut.axis.dot(q - bed.centres[i]));
      cut_planes.emplace_back(cut.axis, h);
    }
    add_solid(spheres[i]);
    piece(Shape::sphere, bed.centres[i], tb.radius[i] + pushed[i], std::move(cut_planes));
  }
  for (auto& m : tb.parts) {  // cap disks (ring_mesh) or bridges, which the test finds not flat and takes whole
    add_solid(m);
    piece(Shape::plane);
  }
  f.weld();
  const WallDelaunaySplits splits = split_wall_triangles_off_delaunay(f, out.pieces, 4.0 * wall_edge, rings);
  round_to_ascii_stl(f);
  out.bed.weld();

  const double domain = c.cross_section_area() * (z1 - z0);
  // The bed's own height, or the window's or period's (or the empty tube's).
  const double section = p.clip || laid.periodic() || n == 0 ? z1 - z0 : top;
  const MeshQuality q = mesh_quality(f);
  out.report = tb.report;
  out.report["parameters"] = to_json(p);
  out.report["domain_m"] = {{"inlet_z", z0}, {"outlet_z", z1}};
  out.exact_volume_m3 = domain - tb.solid_volume;
  out.ends_near_planes = ends;
  out.spheres_near_planes = std::move(near_cuts);
  out.report["fluid_volume_exact_m3"] = out.exact_volume_m3;
  out.report["void_fraction_bed_section_change"] =
      -out.report["solid_volume_change_m3"].get<double>() / (c.cross_section_area() * section);
  out.report["chordal_deviation_d"] = (n > 0 ? *std::max_element(chordal.begin(), chordal.end()) : 0.0) / d;
  out.report["wall_sagitta_d"] = wall_sag / d;
  out.report["sphere_vertices_moved_out_d"] = (n > 0 ? *std::max_element(pushed.begin(), pushed.end()) : 0.0) / d;
  out.report["wall_edge_d"] = wall_edge / d;
  out.report["wall_delaunay"] = {{"missing_before", splits.missing_before},
                                 {"missing_after", splits.missing_after},
                                 {"edges_split", splits.edges_split},
                                 {"rounds", splits.rounds},
                                 {"kept", splits.kept}};
  out.report["triangles"] = f.triangles.size();
  out.report["min_angle_deg"] = q.min_angle_deg;
  out.report["min_edge_d"] = q.min_edge / d;
  out.report["max_edge_d"] = q.max_edge / d;
  return out;
}

FluidSurface build_checked_fluid_surface(const Bed& bed, const SurfaceParams& p,
                                         const std::filesystem::path& bad_triangles_path) {
  const auto t0 = std::chrono::steady_clock::now();
  auto since = [&t0] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  FluidSurface fs = build_fluid_surface(bed, p);
  const double built_at = since();
  fs.check = check_surface(fs.fluid, SelfIntersectionTest::by_pieces, fs.pieces);
  nlohmann::json& j = fs.report;
  j["time_build_s"] = built_at;
  j["time_check_s"] = since() - built_at;
  j["check"] = fs.check.to_json();
  j["fluid_volume_mesh_m3"] = fs.check.volume;
  if (!fs.check.manifold || !fs.check.closed || fs.check.self_intersecting)
    throw std::runtime_error(fmt::format("the fluid surface is not valid ({}); {} defective edges, first at{} please "
                                         "report it with the bed",
                                         fs.check.to_json().dump(), fs.check.defects.size(),
                                         describe_defects(fs.check)));
  j["fluid_volume_relative_error"] = (fs.check.volume - fs.exact_volume_m3) / fs.exact_volume_m3;
  const double min_angle = j["min_angle_deg"].get<double>();
  if (min_angle < p.min_angle_deg) {
    // Say where the needles and slivers are: the nearest particle to each, and all of them in a
    // file for ParaView.
    const TriangleMesh bad = triangles_below_angle(fs.fluid, p.min_angle_deg);
    std::vector<Eigen::Vector3d> centroids;
    for (std::size_t v = 0; v < bad.points.size(); v += 3)
      centroids.push_back((bad.points[v] + bad.points[v + 1] + bad.points[v + 2]) / 3.0);
    const DefectLocations where = locate_defects(bed, centroids, "triangles");
    write_file_atomically(bad_triangles_path, [&](std::ostream& out) {
      write_vtp(out, bad,
                "bedforge " + std::string(kVersion) + " surface triangles below surface.min_angle_deg, lengths in m");
    });
    throw ConvergenceError(fmt::format(
        "surface: {} triangles have an angle below surface.min_angle_deg = {} deg (smallest {:.2f} deg), most near {}; "
        "written to {}. Refine where contacts meet (surface.contact_edge_length_d), widen the gaps ([contacts]), "
        "move the clip window, or lower surface.min_angle_deg",
        bad.triangles.size(), p.min_angle_deg, min_angle, where.summary, bad_triangles_path.string()));
  }
  return fs;
}

}  // namespace bedforge::meshing
