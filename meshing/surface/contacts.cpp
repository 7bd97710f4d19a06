#include "meshing/surface/contacts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/contact_treatment.hpp"

namespace bedforge::meshing {

namespace contact_parts {

ContactTreatment::ContactTreatment(const Bed& bed, const SurfaceParams& p, DomainPlanes planes, ClipContext clip,
                                   std::optional<std::array<double, 2>> between)
    : bed_(bed), p_(p), planes_(planes), clip_(clip), walls_(walls_of(*bed.container)), between_(between) {
  d_ = reference_diameter(bed);
  edge_c_ = p.contact_edge_length_d * d_;
  scale_ = p.treatment == SurfaceParams::Treatment::shrink    ? p.shrink_factor
           : p.treatment == SurfaceParams::Treatment::enlarge ? p.enlarge_factor
                                                              : 1.0;
  const std::size_t n = bed.size();
  out_.radius.resize(n);
  out_.cuts.resize(n);
  out_.cut_names.resize(n);
  out_.kept.resize(n);
  out_.wall_holes.resize(walls_.size());
  out_.planes = planes;
  cut_angle_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    out_.radius[i] = (clip.opening && clip.opening->spheres[i] ? p.shrink_factor : scale_) * 0.5 * bed.diameters[i];
  if (p.treatment == SurfaceParams::Treatment::enlarge) grow_to_join();
  for (std::size_t i = 0; i < n; ++i) {
    const double z = bed.centres[i].z();
    out_.kept[i] = !planes.clip || (z + out_.radius[i] > planes.z0 && z - out_.radius[i] < planes.z1);
    if (!out_.kept[i]) continue;
    volume_ += 4.0 / 3.0 * kPi * std::pow(out_.radius[i], 3);
    area_ += 4.0 * kPi * out_.radius[i] * out_.radius[i];
    volume0_ += 4.0 / 3.0 * kPi * std::pow(0.5 * bed.diameters[i], 3);
    area0_ += kPi * bed.diameters[i] * bed.diameters[i];
    if (between_) {
      between_volume_ += sphere_slab_volume(out_.radius[i], z, (*between_)[0], (*between_)[1]);
      between_volume0_ += sphere_slab_volume(0.5 * bed.diameters[i], z, (*between_)[0], (*between_)[1]);
    }
  }
}

TreatedBed ContactTreatment::run() {
  const std::size_t n = bed_.size();
  const double tolerance = treat_below(p_.treatment);
  // Skin: the treatment's tolerance, what a shrink opens and an enlarge closes, and the join
  // gap: every contact of the bed is seen, and every gap the smallest-gap report must cover.
  const double d_max = largest_diameter(bed_);
  const double join = p_.treatment == Treatment::enlarge ? p_.enlarge_join_gap_d * d_ : 0.0;
  const double resized = std::max(std::abs(1.0 - scale_), clip_.opening ? 1.0 - p_.shrink_factor : 0.0);
  NeighbourList nl(std::max(tolerance, 0.0) + resized * d_max + join + 1e-3 * d_);
  nl.build(bed_.centres, out_.radius, *bed_.container);
  const double wall_pad = 0.6 * p_.edge_length_d * d_;  // the wall mesh keeps its holes this clear of its ends
  std::vector<int> partners;
  for (std::size_t i = 0; i < n; ++i) {
    // By index, not in the list's order (its grid follows the skin, which a window's opened
    // contacts widen): a sphere's cuts then come in one order in every window of a bed, and the
    // sphere is meshed alike in each (pieces cut from widened windows rely on it).
    partners.assign(nl.of(i).begin(), nl.of(i).end());
    std::sort(partners.begin(), partners.end());
    for (int j : partners)
      if (static_cast<std::size_t>(j) > i) {
        const Marks m = mark(i, j);
        const Counts before = counts();
        pair(i, j, nl);
        record(key(i, j), m, i, j, 0.0);
        count_between(key(i, j), before);
      }
    for (const Wall& w : walls_) {
      const Marks m = mark(i, i);
      const Counts before = counts();
      wall(i, w, nl);
      record(key(i, n + w.index), m, i, i, wall_pad);
      count_between(key(i, n + w.index), before);
    }
    ends(i);
  }
  for (std::size_t i = 0; i < n; ++i) check_cuts(i);
  if (!(min_gap_ > 0.0)) throw InputError(gap_error_);
  out_.solid_volume = volume_;
  if (between_) out_.solid_volume_between_m3 = between_volume_, out_.untreated_volume_between_m3 = between_volume0_;
  out_.min_concave_wall_gap = out_.bed_min_concave_wall_gap = min_concave_wall_gap_;
  auto angle = [](double a) { return std::isfinite(a) ? nlohmann::json(a * 180.0 / kPi) : nlohmann::json(nullptr); };
  out_.report = {
      {"contacts_treated",
       {{"particle_particle", treated_pp_},
        {"particle_wall", treated_pw_},
        {"by_kind", {{"bridge", bridges_}, {"cap", caps_}, {"union", unions_}}},
        {"grown_to_meet_the_wall", grown_to_wall_},
        {"grown_to_meet_a_sphere", grown_to_sphere_}}},
      {"solid_volume_change_relative", volume_ / volume0_ - 1.0},
      {"solid_volume_change_m3", volume_ - volume0_},
      {"particle_area_change_relative", area_ / area0_ - 1.0},
      {"smallest_gap_d", {{"particle_particle", min_pair_gap_ / d_}, {"particle_wall", min_wall_gap_ / d_}}},
      {"smallest_fluid_wedge_angle_deg", angle(min_wedge_)},
      {"solid_volume_exact_m3", volume_}};
  if (between_) {
    const Counts& b = between_counts_;
    out_.report["contacts_treated_between"] = {{"particle_particle", b[0]},
                                               {"particle_wall", b[1]},
                                               {"by_kind", {{"bridge", b[2]}, {"cap", b[3]}, {"union", b[4]}}}};
  }
  if (clip_.opening)
    out_.report["opened_at_clip_planes"] = {{"particle_particle", opened_pp_}, {"particle_wall", opened_pw_}};
  return std::move(out_);
}

void ContactTreatment::grow_to_join() {
  const std::size_t n = bed_.size();
  const double f = p_.enlarge_factor - 1.0, join = p_.enlarge_join_gap_d * d_;
  auto r0 = [&](std::size_t i) { return 0.5 * bed_.diameters[i]; };
  std::vector<double> reach;  // per wall
  for (const Wall& w : walls_)
    reach.push_back(w.concave() ? std::max(join, 2.0 * ring_sagitta(w.R, p_.edge_length_d * d_)) : join);
  for (int round = 0;; ++round) {
    std::vector<double> grow(n, 0.0);
    std::string last;
    for (std::size_t i = 0; i < n; ++i)
      for (const Wall& w : walls_) {
        const double gap = w.gap(bed_.centres[i], out_.radius[i]), overlap = f * r0(i);
        if (gap <= -0.5 * overlap || gap >= reach[w.index]) continue;
        grow[i] = std::max(grow[i], gap + overlap);
        ++grown_to_wall_;
        last = fmt::format("sphere {} and the {}", i, w.name);
      }
    NeighbourList nl(join);
    nl.build(bed_.centres, out_.radius, *bed_.container);
    for (std::size_t i = 0; i < n; ++i)
      for (int j : nl.of(i)) {
        if (static_cast<std::size_t>(j) <= i) continue;
        const double gap = (bed_.centres[j] - bed_.centres[i]).norm() - out_.radius[i] - out_.radius[j];
        const double overlap = f * (r0(i) + r0(j));
        if (gap <= -0.5 * overlap || gap >= join) continue;
        const double g = 0.5 * (gap + overlap);
        grow[i] = std::max(grow[i], g);
        grow[j] = std::max(grow[j], g);
        ++grown_to_sphere_;
        last = fmt::format("spheres {} and {}", i, j);
      }
    if (last.empty()) return;
    if (round == kJoinRounds)
      throw InputError(fmt::format("contacts.enlarge_join_gap_d = {}: after {} rounds of growing spheres to join "
                                   "their near neighbours, {} are still nearer than that; allowed: a smaller "
                                   "enlarge_join_gap_d or another treatment",
                                   p_.enlarge_join_gap_d, kJoinRounds, last));
    for (std::size_t i = 0; i < n; ++i) out_.radius[i] += grow[i];
  }
}

double ContactTreatment::treat_below(Treatment t) const {
  switch (t) {
    case Treatment::bridge: return p_.bridge_gap_d * d_;
    case Treatment::cap: return p_.cap_gap_d * d_;
    case Treatment::enlarge: return 0.0;
    default: return -std::numeric_limits<double>::infinity();
  }
}

void ContactTreatment::gap_left(double gap, const Wall* wall, const std::string& what) {
  double& m = wall ? min_wall_gap_ : min_pair_gap_;
  m = std::min(m, gap);
  if (wall && wall->concave()) min_concave_wall_gap_ = std::min(min_concave_wall_gap_, gap);
  if (gap < min_gap_) {
    min_gap_ = gap;
    // A box with periodic sides (periodic on every side, here laid out along z) takes spheres
    // apart only (build_periodic_box_surface).
    const std::string allowed =
        bed_.container->periodicity().lateral()
            ? "contacts.treatment = \"shrink\" with a contacts.shrink_factor that parts them (a box periodic on "
              "every side joins no contact)"
            : "a treatment that opens or joins every contact (contacts.treatment, contacts.wall_treatment, their "
              "factors and gaps)";
    gap_error_ = fmt::format("{} still touch{} or overlap{} by {:.3g} d after the '{}' treatment; allowed: {}", what,
                             wall ? "es" : "", wall ? "s" : "", -gap / d_, treatment_name(p_.treatment), allowed);
  }
}

void ContactTreatment::add_cut(std::size_t i, SphereCut cut, const std::string& name, double angle) {
  out_.cuts[i].push_back(std::move(cut));
  out_.cut_names[i].push_back(name);
  cut_angle_[i].push_back(angle);
}

ContactTreatment::Marks ContactTreatment::mark(std::size_t i, std::size_t j) const {
  Marks m{out_.cuts[i].size(), out_.cuts[j].size(), out_.parts.size(), {}};
  if (clip_.record_extents)
    for (const auto& h : out_.wall_holes) m.holes.push_back(h.size());
  return m;
}

void ContactTreatment::record(long long k, const Marks& m, std::size_t i, std::size_t j, double pad) {
  if (!clip_.record_extents) return;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  auto take = [&](const Eigen::Vector3d& q) { lo = std::min(lo, q.z()), hi = std::max(hi, q.z()); };
  for (auto [s, from] : {std::pair{i, m.cuts_i}, std::pair{j, m.cuts_j}}) {
    const Eigen::Vector3d& c = bed_.centres[s];
    const double r = out_.radius[s];
    for (std::size_t c_new = from; c_new < out_.cuts[s].size(); ++c_new) {
      const SphereCut& cut = out_.cuts[s][c_new];
      for (const auto& q : cut.loop) take(q);
      take(c + r * cut.axis);
      for (const Eigen::Vector3d& pole : {Eigen::Vector3d(c + r * Eigen::Vector3d::UnitZ()), Eigen::Vector3d(c - r * Eigen::Vector3d::UnitZ())})
        if (cut.removed(pole)) take(pole);
    }
  }
  for (std::size_t part = m.parts; part < out_.parts.size(); ++part)
    for (const auto& q : out_.parts[part].points) take(q);
  for (std::size_t w = 0; w < m.holes.size(); ++w)
    for (std::size_t hole = m.holes[w]; hole < out_.wall_holes[w].size(); ++hole)
      for (const auto& q : out_.wall_holes[w][hole].loop) take(q);
  if (lo <= hi) extents_[k] = {lo - pad, hi + pad};
}

void ContactTreatment::count_between(long long k, const Counts& before) {
  if (!between_) return;
  const auto it = extents_.find(k);
  if (it == extents_.end() || it->second.second < (*between_)[0] || it->second.first > (*between_)[1]) return;
  const Counts now = counts();
  for (std::size_t q = 0; q < now.size(); ++q) between_counts_[q] += now[q] - before[q];
}

bool ContactTreatment::beyond_planes(long long k, const std::string& who) const {
  if (!clip_.surveyed) return false;
  const auto it = clip_.surveyed->find(k);
  if (it == clip_.surveyed->end()) return false;
  const auto [lo, hi] = it->second;
  if (hi <= planes_.z0 || lo >= planes_.z1) return true;
  if (lo < planes_.z0 || hi > planes_.z1)
    throw InputError(fmt::format("the treated contact of {} crosses a clip plane", who));
  return false;
}

bool ContactTreatment::open(long long k, const std::string& who, double gap, bool kept, const Wall* wall) {
  if (!clip_.opening || !clip_.opening->contacts.count(k)) return false;
  if (!kept) return true;
  if (!(gap > 0.0))
    throw InputError(fmt::format("{} meet at a clip plane, so they are shrunk by contacts.shrink_factor = {} "
                                 "instead of treated, but still overlap by {:.3g} d; allowed: a smaller "
                                 "shrink_factor, or a clip window whose planes find room between the contacts "
                                 "(surface.clip_shift_d)",
                                 who, p_.shrink_factor, -gap / d_));
  ++(wall ? opened_pw_ : opened_pp_);
  gap_left(gap, wall, who);
  return true;
}

Frame ContactTreatment::plane_cut(std::size_t i, const Eigen::Vector3d& a, double h, double rho, int n, double jitter,
                const std::string& name, std::optional<Eigen::Vector3d> at, double turn) {
  const Eigen::Vector3d& c = bed_.centres[i];
  const double r = out_.radius[i];
  const Frame f = Frame::along(at.value_or(c + h * a), a).turned(turn);
  SphereCut cut;
  // A clip plane's loop (`at` given) runs counterclockwise seen from above whichever side is
  // removed: the slabs on either side of a plane (meshing/volume/slab_mesh.hpp) share it bit for bit.
  cut.loop = circle_loop(at ? Frame::along(*at, Eigen::Vector3d::UnitZ()) : f, rho, n);
  cut.spacing = 2.0 * kPi * rho / n;
  cut.jitter = jitter;
  cut.axis = a;
  cut.removed = [c, a, h](const Eigen::Vector3d& q) { return (q - c).dot(a) > h; };
  add_cut(i, std::move(cut), name, std::acos(std::clamp(h / r, -1.0, 1.0)));
  volume_ -= cap_volume(r, r - h);
  between_volume_ -= cap_between(c, r, a, h);
  area_ -= cap_area(r, r - h);
  return f;
}

double ContactTreatment::between(const Eigen::Vector3d& c, const Eigen::Vector3d& a, double t0, double t1,
                                 const std::function<double(double)>& radius) const {
  return between_ ? revolution_slab_volume(c.z(), a.z(), t0, t1, radius, (*between_)[0], (*between_)[1]) : 0.0;
}

double ContactTreatment::cap_between(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& a, double h) const {
  return between(c, a, h, r, [r](double t) { return std::sqrt(std::max(0.0, r * r - t * t)); });
}

void ContactTreatment::check_cuts(std::size_t i) {
  const auto& cuts = out_.cuts[i];
  const auto& radius = cut_angle_[i];
  for (std::size_t k = 0; k < cuts.size(); ++k)
    for (std::size_t l = k + 1; l < cuts.size(); ++l) {
      const double between = std::acos(std::clamp(cuts[k].axis.dot(cuts[l].axis), -1.0, 1.0));
      if (between - radius[k] - radius[l] <= 0.0)
        throw InputError(fmt::format("sphere {}: its {} and its {} overlap on the sphere; allowed: a narrower "
                                     "contacts.bridge_diameter_d, a smaller cap or enlarge, or another treatment",
                                     i, out_.cut_names[i][k], out_.cut_names[i][l]));
    }
}

}  // namespace contact_parts

TreatedBed treat_contacts_measured_between(const Bed& bed, const SurfaceParams& p, double z1, double z2) {
  const double inf = std::numeric_limits<double>::infinity();
  return contact_parts::ContactTreatment(bed, p, {-inf, inf, false}, {.record_extents = true}, std::array<double, 2>{z1, z2})
      .run();
}

TreatedBed treat_contacts(const Bed& bed, const SurfaceParams& p, DomainPlanes planes) {
  if (!planes.clip) return contact_parts::ContactTreatment(bed, p, planes).run();
  // Survey the whole bed's contacts, place the clip planes clear of them and of every sphere's
  // top and bottom, then treat the window.
  const double inf = std::numeric_limits<double>::infinity();
  contact_parts::ContactTreatment survey(bed, p, {-inf, inf, false}, {.record_extents = true});
  const TreatedBed whole = survey.run();
  const ClipPlacement placed = place_clip_planes(bed, p, planes, whole.radius, survey.extents());
  const ClipOpening* opening = placed.opening.contacts.empty() ? nullptr : &placed.opening;
  TreatedBed out =
      contact_parts::ContactTreatment(bed, p, placed.planes, {.surveyed = &survey.extents(), .opening = opening}).run();
  // The curved walls' edge follows their narrowest gap: taken over the whole bed, every window
  // of one bed (the slabs of one mesh) rims a plane they share with the same vertices.
  out.min_concave_wall_gap = std::min(out.min_concave_wall_gap, whole.min_concave_wall_gap);
  out.bed_min_concave_wall_gap = whole.min_concave_wall_gap;
  out.report["clip"] = placed.report;
  return out;
}

namespace {

// The bridges and caps of a laid-out periodic section that its planes cross (by `extents`, a
// survey of the whole layout), to be opened as a clip window opens them; a sphere and its image
// a period away shrink alike, and so do their contacts' images, so that the two planes see the
// same solid.
ClipOpening periodic_opening(const UnwrappedSection& section, const SurfaceParams& p, const ContactExtents& extents) {
  const Bed& bed = section.bed;
  const std::size_t n = bed.size();
  const double reach = opening_reach(bed, p);
  std::vector<int> image(n, -1);
  for (std::size_t i = 0; i < section.twin.size(); ++i)
    if (const int t = section.twin[i]; t >= 0) image[i] = t, image[static_cast<std::size_t>(t)] = static_cast<int>(i);
  ClipOpening out;
  out.spheres.assign(n, 0);
  for (const auto& [k, range] : extents) {
    if (!reaches_plane(range, section.planes.z0, reach) && !reaches_plane(range, section.planes.z1, reach)) continue;
    const auto [i, j] = contact_of(k, n);
    out.contacts.insert(k);
    // The same contact at the other plane, where both spheres have an image there.
    const int ii = image[i], jj = j < n ? image[j] : static_cast<int>(j);
    if (ii >= 0 && jj >= 0) {
      const auto [a, b] = std::minmax(static_cast<std::size_t>(ii), static_cast<std::size_t>(jj));
      out.contacts.insert(j < n ? contact_key(a, b, n) : contact_key(static_cast<std::size_t>(ii), j, n));
    }
    for (std::size_t s : {i, j})
      if (s < n) {
        out.spheres[s] = 1;
        if (image[s] >= 0) out.spheres[static_cast<std::size_t>(image[s])] = 1;
      }
  }
  return out;
}

}  // namespace

TreatedBed treat_periodic_section(const UnwrappedSection& section, const SurfaceParams& p) {
  // Bridges and caps that the planes cross are opened (a survey of the layout finds them).
  ContactExtents extents;
  ClipOpening opening;
  const bool opens = opens_contacts_at_periodic_planes(p);
  if (opens) {
    const double inf = std::numeric_limits<double>::infinity();
    contact_parts::ContactTreatment survey(section.bed, p, {-inf, inf, false}, {.record_extents = true});
    survey.run();
    extents = survey.extents();
    opening = periodic_opening(section, p, extents);
  }
  const contact_parts::ClipContext context =
      opens ? contact_parts::ClipContext{.surveyed = &extents, .opening = &opening} : contact_parts::ClipContext{};
  TreatedBed out = contact_parts::ContactTreatment(section.bed, p, section.planes, context).run();
  // A sphere crossing the upper plane takes its twin's loop on the lower one, moved up a period:
  // the outlet's holes are then the inlet's, bit for bit in x and y, as a cyclic patch needs.
  auto plane_cut = [&](std::size_t i, const char* name) -> SphereCut& {
    for (std::size_t k = 0; k < out.cuts[i].size(); ++k)
      if (out.cut_names[i][k] == name) return out.cuts[i][k];
    throw std::logic_error(fmt::format("sphere {} crosses a periodic plane but has no {} cut", i, name));
  };
  for (std::size_t i = 0; i < section.twin.size(); ++i) {
    if (section.twin[i] < 0) continue;
    SphereCut& upper = plane_cut(i, "outlet clip plane");
    upper.loop = plane_cut(static_cast<std::size_t>(section.twin[i]), "inlet clip plane").loop;
    for (Eigen::Vector3d& q : upper.loop) q.z() = section.planes.z1;
  }
  out.outlet_holes.clear();  // the outlet is the inlet's mesh, moved up a period
  long opened = 0;
  if (out.report.contains("opened_at_clip_planes"))
    opened = out.report["opened_at_clip_planes"]["particle_particle"].get<long>() +
             out.report["opened_at_clip_planes"]["particle_wall"].get<long>();
  out.report["periodic_planes_m"] = {{"lower", section.planes.z0}, {"upper", section.planes.z1},
                                     {"clearance_d", section.clearance / reference_diameter(section.bed)},
                                     {"narrowest_gap_d", section.narrowest_gap / reference_diameter(section.bed)},
                                     {"contacts_opened", opened}};
  return out;
}

}  // namespace bedforge::meshing
