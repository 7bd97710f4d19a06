#include "meshing/contacts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "core/intersection_volumes.hpp"
#include "core/quadrature.hpp"
#include "core/error.hpp"
#include "core/neighbour_list.hpp"
#include "meshing/clip_planes.hpp"

namespace bedforge::meshing {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kContact = 1e-4;  // a gap below this (in d) is a contact, as in the packers

// Volume and curved area of the cap of height H cut from a sphere of radius r.
double cap_volume(double r, double H) { return kPi * H * H * (3.0 * r - H) / 3.0; }
double cap_area(double r, double H) { return 2.0 * kPi * r * H; }

// Distance from point q to the segment [a, b].
double segment_distance(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((q - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (q - (a + t * ab)).norm();
}

// A wall of the container as the treatment sees it: a cylinder about the z axis (the fluid
// inside it, or outside for an annulus's inner wall) or a plane n.p = k with n out of the fluid.
struct Wall {
  std::string name;
  int index = 0;  // into TreatedBed::wall_holes
  bool plane = false;
  double R = 0.0;
  bool inner = false;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  double k = 0.0;
  // Distance from p to the wall, negative beyond it (in a cylinder: radially).
  double reach(const Eigen::Vector3d& p) const {
    if (plane) return k - n.dot(p);
    const double rho = std::hypot(p.x(), p.y());
    return inner ? rho - R : R - rho;
  }
  double gap(const Eigen::Vector3d& c, double r) const { return reach(c) - r; }
  bool beyond(const Eigen::Vector3d& p) const { return reach(p) < 0.0; }
  // A cylinder around the fluid: its facets lie inside it, towards the spheres.
  bool concave() const { return !plane && !inner; }
  // Unit direction from p to the nearest point of the wall.
  Eigen::Vector3d towards(const Eigen::Vector3d& p) const {
    if (plane) return n;
    const double rho = std::hypot(p.x(), p.y());
    const Eigen::Vector3d radial = rho > 0.0 ? Eigen::Vector3d(p.x() / rho, p.y() / rho, 0.0) : Eigen::Vector3d::UnitX();
    return inner ? Eigen::Vector3d(-radial) : radial;
  }
  // Parameter t > 0 where the line p + t a (a unit; horizontal for a cylinder) first meets the
  // wall; NaN if never.
  double hit(const Eigen::Vector3d& p, const Eigen::Vector3d& a) const {
    if (plane) {
      const double na = n.dot(a);
      return na > 0.0 ? (k - n.dot(p)) / na : std::numeric_limits<double>::quiet_NaN();
    }
    const double b = p.x() * a.x() + p.y() * a.y(), c = p.x() * p.x() + p.y() * p.y() - R * R, disc = b * b - c;
    if (disc < 0.0) return std::numeric_limits<double>::quiet_NaN();
    return inner ? -b - std::sqrt(disc) : -b + std::sqrt(disc);
  }
};

std::vector<Wall> walls_of(const Container& c) {
  if (const auto* cyl = dynamic_cast<const Cylinder*>(&c)) return {Wall{"wall", 0, false, cyl->radius()}};
  if (const auto* ann = dynamic_cast<const Annulus*>(&c))
    return {Wall{"wall", 0, false, ann->outer_radius()}, Wall{"inner wall", 1, false, ann->inner_radius(), true}};
  if (const auto* box = dynamic_cast<const Box*>(&c)) {
    if (box->periodicity().any())
      throw InputError("container.periodic_x/periodic_y = true: the surface stage meshes walled boxes only (a periodic "
                       "fluid domain needs matching periodic patches, not made here); allowed: a box with walls on "
                       "every side, a cylinder or an annulus");
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

// How one treatment of the bed stands to the clip planes.
struct ClipContext {
  bool record_extents = false;                 // a survey of the whole bed: record each treated contact's z extent
  const ContactExtents* surveyed = nullptr;    // the window: the survey's extents, to leave out contacts beyond the planes
  const ClipOpening* opening = nullptr;        // the window: contacts opened at the planes instead of treated
};

// Treats the contacts of a bed once: resizes the spheres, cuts them where they meet each other,
// a wall or a clip plane, adds the bridges, caps and unions, and measures what is left.
class ContactTreatment {
 public:
  ContactTreatment(const Bed& bed, const SurfaceParams& p, DomainPlanes planes, ClipContext clip = {})
      : bed_(bed), p_(p), planes_(planes), clip_(clip), walls_(walls_of(*bed.container)) {
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
    }
  }

  TreatedBed run() {
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
    for (std::size_t i = 0; i < n; ++i) {
      for (int j : nl.of(i))
        if (static_cast<std::size_t>(j) > i) {
          const Marks m = mark(i, j);
          pair(i, j, nl);
          record(key(i, j), m, i, j, 0.0);
        }
      for (const Wall& w : walls_) {
        const Marks m = mark(i, i);
        wall(i, w, nl);
        record(key(i, n + w.index), m, i, i, wall_pad);
      }
      ends(i);
    }
    for (std::size_t i = 0; i < n; ++i) check_cuts(i);
    if (!(min_gap_ > 0.0)) throw InputError(gap_error_);
    out_.solid_volume = volume_;
    out_.min_concave_wall_gap = min_concave_wall_gap_;
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
    if (clip_.opening)
      out_.report["opened_at_clip_planes"] = {{"particle_particle", opened_pp_}, {"particle_wall", opened_pw_}};
    return std::move(out_);
  }

  const ContactExtents& extents() const { return extents_; }

 private:
  using Treatment = SurfaceParams::Treatment;

  // Enlarging leaves the pairs that were just out of its reach a sliver of a gap (1e-6 d at
  // N = 1e4), which no volume mesh resolves, and those just within it a joint so thin that the
  // fluid around it is a wedge of a fraction of a degree (0.53 degrees at a = 5, N = 1000,
  // where no tetrahedron met the gate). So a sphere left nearer than `enlarge_join_gap_d` to
  // another sphere or to a wall, or overlapping it by less than half what the enlargement gives
  // spheres that touched (their radii x (factor - 1)), is grown further to overlap it by that
  // whole amount, and joined like the others. A curved wall's facets lie inside it by up to
  // their sagitta: there the reach is at least twice that. Growing can bring a sphere near a
  // third one, so this repeats until no such gap or joint is left.
  void grow_to_join() {
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
  static constexpr int kJoinRounds = 20;

  // Gap below which a contact is treated (pairs and walls share the tolerance of their treatment).
  double treat_below(Treatment t) const {
    switch (t) {
      case Treatment::bridge: return p_.bridge_gap_d * d_;
      case Treatment::cap: return p_.cap_gap_d * d_;
      case Treatment::enlarge: return 0.0;
      default: return -std::numeric_limits<double>::infinity();
    }
  }

  // `wall`: the wall of the gap, null for a pair's.
  void gap_left(double gap, const Wall* wall, const std::string& what) {
    double& m = wall ? min_wall_gap_ : min_pair_gap_;
    m = std::min(m, gap);
    if (wall && wall->concave()) min_concave_wall_gap_ = std::min(min_concave_wall_gap_, gap);
    if (gap < min_gap_) {
      min_gap_ = gap;
      gap_error_ = fmt::format("{} still touch{} or overlap{} by {:.3g} d after the '{}' treatment; allowed: a "
                               "treatment that opens or joins every contact (contacts.treatment, "
                               "contacts.wall_treatment, their factors and gaps)",
                               what, wall ? "es" : "", wall ? "s" : "", -gap / d_, treatment_name(p_.treatment));
    }
  }

  // `angle`: the largest angle from the cut's axis to its loop, seen from the centre.
  void add_cut(std::size_t i, SphereCut cut, const std::string& name, double angle) {
    out_.cuts[i].push_back(std::move(cut));
    out_.cut_names[i].push_back(name);
    cut_angle_[i].push_back(angle);
  }

  long long key(std::size_t i, std::size_t j) const { return contact_key(i, j, bed_.size()); }

  // How much geometry there is before a contact is treated, so its extent can be taken after.
  struct Marks {
    std::size_t cuts_i, cuts_j, parts;
    std::vector<std::size_t> holes;
  };
  Marks mark(std::size_t i, std::size_t j) const {
    Marks m{out_.cuts[i].size(), out_.cuts[j].size(), out_.parts.size(), {}};
    if (clip_.record_extents)
      for (const auto& h : out_.wall_holes) m.holes.push_back(h.size());
    return m;
  }
  // The z extent of what the contact (i, j) added since `m` (the cut caps included), widened by `pad`.
  void record(long long k, const Marks& m, std::size_t i, std::size_t j, double pad) {
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
  // With clip planes: true when the contact (as surveyed) lies wholly beyond them, so is left
  // out; InputError when it crosses one (the planes were placed clear of every contact).
  bool beyond_planes(long long k, const std::string& who) const {
    if (!clip_.surveyed) return false;
    const auto it = clip_.surveyed->find(k);
    if (it == clip_.surveyed->end()) return false;
    const auto [lo, hi] = it->second;
    if (hi <= planes_.z0 || lo >= planes_.z1) return true;
    if (lo < planes_.z0 || hi > planes_.z1)
      throw InputError(fmt::format("the treated contact of {} crosses a clip plane", who));
    return false;
  }

  // Contact k (`wall`: its wall, null for a pair) when it is opened at a clip plane: its gap is
  // left as it is (nothing to do when a sphere of it is left out); returns false for any other
  // contact. InputError when shrinking did not open it (an overlap deeper than the shrink).
  bool open(long long k, const std::string& who, double gap, bool kept, const Wall* wall) {
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

  // A planar cut of sphere i at distance h along axis a (unit), its loop of n vertices on the
  // circle of radius rho (given, so a bridge's loop is exactly its tube's) about `at` (default
  // c + h a), its rings jittered by `jitter` (SphereCut); returns the loop's frame.
  Frame plane_cut(std::size_t i, const Eigen::Vector3d& a, double h, double rho, int n, double jitter,
                  const std::string& name, std::optional<Eigen::Vector3d> at = std::nullopt, double turn = 0.0) {
    const Eigen::Vector3d& c = bed_.centres[i];
    const double r = out_.radius[i];
    const Frame f = Frame::along(at.value_or(c + h * a), a).turned(turn);
    SphereCut cut;
    // A clip plane's loop (`at` given) runs counterclockwise seen from above whichever side is
    // removed: the slabs on either side of a plane (meshing/slab_mesh.hpp) share it bit for bit.
    cut.loop = circle_loop(at ? Frame::along(*at, Eigen::Vector3d::UnitZ()) : f, rho, n);
    cut.spacing = 2.0 * kPi * rho / n;
    cut.jitter = jitter;
    cut.axis = a;
    cut.removed = [c, a, h](const Eigen::Vector3d& q) { return (q - c).dot(a) > h; };
    add_cut(i, std::move(cut), name, std::acos(std::clamp(h / r, -1.0, 1.0)));
    volume_ -= cap_volume(r, r - h);
    area_ -= cap_area(r, r - h);
    return f;
  }

  // Spheres i and j: a contact closer than the treatment's gap is capped, joined or bridged
  // (cut_i, cut_j: the distances from each centre to its cut plane along the line of centres);
  // any other is left as the gap it is.
  void pair(std::size_t i, std::size_t j, const NeighbourList& nl) {
    const Eigen::Vector3d &ci = bed_.centres[i], &cj = bed_.centres[j];
    const double ri = out_.radius[i], rj = out_.radius[j], dist = (cj - ci).norm(), gap = dist - ri - rj;
    const std::string who = fmt::format("spheres {} and {}", i, j);
    if (open(key(i, j), who, gap, out_.kept[i] && out_.kept[j], nullptr)) return;
    const bool treated = gap < treat_below(p_.treatment);
    if ((treated && beyond_planes(key(i, j), who)) || !out_.kept[i] || !out_.kept[j]) return;
    if (!treated) {
      if (p_.treatment == Treatment::shrink && dist - (ri + rj) / scale_ <= kContact * d_) ++treated_pp_;
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
    area_ += 2.0 * kPi * bridge_radius * L - cap_area(rj, rj - cut_j);
    out_.parts.push_back(tube_mesh(f, bridge_radius, n, length, edge_c_, true, "particles"));
    wedge(0.5 * kPi + std::asin(bridge_radius / std::max(ri, rj)));
    ++bridges_;
    gap_left(L, nullptr, who);
  }

  // Sphere i and wall w, as pair() with the wall's own treatment.
  void wall(std::size_t i, const Wall& w, const NeighbourList& nl) {
    const Eigen::Vector3d& c = bed_.centres[i];
    const double r = out_.radius[i], gap = w.gap(c, r);
    const std::string who = fmt::format("sphere {} and the {}", i, w.name);
    if (open(key(i, bed_.size() + w.index), who, gap, out_.kept[i], &w)) return;
    const Treatment t = p_.wall_treatment;
    const bool treated = gap < treat_below(t);
    if ((treated && beyond_planes(key(i, bed_.size() + w.index), who)) || !out_.kept[i]) return;
    if (!treated) {
      if (t == Treatment::shrink && w.gap(c, r / scale_) <= kContact * d_) ++treated_pw_;
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
    const int n = ring_points(bridge_radius, edge_c_);
    const Frame f = plane_cut(i, a, h, bridge_radius, n, kBreakCocircular, "bridge to the " + w.name);
    const GeneratorLength length = [f, w](double x, double y) { return w.hit(f.to_world(Eigen::Vector3d(x, y, 0.0)), f.w); };
    double shortest = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 64; ++j) {
      const double l = length(bridge_radius * std::cos(2 * kPi * j / 64), bridge_radius * std::sin(2 * kPi * j / 64));
      shortest = std::min(shortest, std::isnan(l) ? -1.0 : l);
    }
    if (!(shortest > 0.0))
      throw InputError(fmt::format("{}: no room for a bridge (the sphere crosses the wall or the bridge misses it)", who));
    const Eigen::Vector3d from = f.origin, to = f.origin + length(0.0, 0.0) * a;
    for (int k : nl.of(i))
      if (segment_distance(bed_.centres[k], from, to) < out_.radius[k] + bridge_radius)
        throw InputError(fmt::format("the bridge between {} would cross sphere {}", who, k));
    holes.push_back({tube_end_loop(f, bridge_radius, n, length, edge_c_), 2.0 * kPi * bridge_radius / n, static_cast<int>(i)});
    out_.parts.push_back(tube_mesh(f, bridge_radius, n, length, edge_c_, true, "particles"));
    // Volume and lateral area of the bridge: polar quadrature over its cross-section (smooth
    // integrand: Gauss-Legendre in radius, trapezoid in angle, both spectrally accurate).
    constexpr int kAngles = 128;
    double vol = 0.0, lateral = 0.0;
    for (int j = 0; j < kAngles; ++j) {
      const double th = 2.0 * kPi * j / kAngles, cs = std::cos(th), sn = std::sin(th);
      lateral += length(bridge_radius * cs, bridge_radius * sn) * bridge_radius * 2.0 * kPi / kAngles;
      vol += integrate_pieces({0.0, bridge_radius}, [&](double s) { return length(s * cs, s * sn) * s; }) * 2.0 * kPi /
             kAngles;
    }
    volume_ += vol;
    area_ += lateral;
    wedge(0.5 * kPi + std::asin(bridge_radius / r));
    ++bridges_;
    gap_left(shortest, &w, who);
  }

  // Sphere i crossing wall w: its mesh stops on the curve where they meet, and the wall gets a hole there.
  void wall_union(std::size_t i, const Wall& w, const Eigen::Vector3d& a) {
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
    add_cut(i, std::move(cut), "union with the " + w.name, beta_max);
    open_hole(i, holes, -w.towards(out_.cuts[i].back().loop[0]));
    const double rho = std::hypot(c.x(), c.y());
    const double inside = sphere_cylinder_volume(r, rho, c.z(), w.R, c.z() - r, c.z() + r);
    volume_ -= w.inner ? inside : 4.0 / 3.0 * kPi * r * r * r - inside;
    area_ -= removed_area;
  }

  // Sphere i's last cut is where it crosses a wall or clip plane: the loop is a hole there, and
  // the fluid's wedge between the sphere and that surface (normal `into_fluid` at the loop) is measured.
  void open_hole(std::size_t i, std::vector<WallHole>& holes, const Eigen::Vector3d& into_fluid) {
    const SphereCut& cut = out_.cuts[i].back();
    holes.push_back({cut.loop, cut.spacing, static_cast<int>(i)});
    wedge(kPi - std::acos(std::clamp(((cut.loop[0] - bed_.centres[i]) / out_.radius[i]).dot(into_fluid), -1.0, 1.0)));
  }

  // Sphere i crossing a plane at distance h along a (unit, into the part removed): cut on the
  // exact circle (about `at` when given, so its loop lies exactly in the plane), a hole in the plane.
  void cross_plane(std::size_t i, const Eigen::Vector3d& a, double h, const std::string& name,
                   std::vector<WallHole>& holes, std::optional<Eigen::Vector3d> at) {
    const double r = out_.radius[i], rho = std::sqrt(std::max(0.0, r * r - h * h));
    plane_cut(i, a, h, rho, ring_points(rho, edge_c_), kBreakCocircular, name, at);
    open_hole(i, holes, -a);
  }

  // Spheres must stay clear of the inlet and outlet planes, or are cut by them when they clip.
  void ends(std::size_t i) {
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

  // Sphere i cut by the inlet (outlet) clip plane: its loop, exactly in the plane, is a hole in
  // that patch. The untreated reference loses the same cap of the untreated sphere.
  void clip(std::size_t i, bool outlet) {
    const Eigen::Vector3d& c = bed_.centres[i];
    const double z = outlet ? planes_.z1 : planes_.z0, h = outlet ? z - c.z() : c.z() - z;
    const Eigen::Vector3d a = outlet ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(-Eigen::Vector3d::UnitZ());
    cross_plane(i, a, h, outlet ? "outlet clip plane" : "inlet clip plane", outlet ? out_.outlet_holes : out_.inlet_holes,
                Eigen::Vector3d(c.x(), c.y(), z));
    const double r0 = 0.5 * bed_.diameters[i], H0 = std::clamp(r0 - h, 0.0, 2.0 * r0);
    volume0_ -= cap_volume(r0, H0);
    area0_ -= cap_area(r0, H0);
  }

  // The cuts on one sphere must not overlap: the angle between their axes must exceed the sum
  // of their angular radii.
  void check_cuts(std::size_t i) {
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

  void wedge(double angle) { min_wedge_ = std::min(min_wedge_, angle); }

  const Bed& bed_;
  const SurfaceParams& p_;
  DomainPlanes planes_;
  ClipContext clip_;
  std::vector<Wall> walls_;
  ContactExtents extents_;
  double d_ = 0.0, edge_c_ = 0.0, scale_ = 1.0;
  TreatedBed out_;
  double volume_ = 0.0, area_ = 0.0, volume0_ = 0.0, area0_ = 0.0;
  long grown_to_wall_ = 0, grown_to_sphere_ = 0;  // enlarged spheres grown further to join a wall, pairs grown to join
  double min_pair_gap_ = std::numeric_limits<double>::infinity(), min_wall_gap_ = min_pair_gap_, min_gap_ = min_pair_gap_;
  double min_concave_wall_gap_ = min_pair_gap_;
  double min_wedge_ = std::numeric_limits<double>::infinity();
  std::string gap_error_;
  long treated_pp_ = 0, treated_pw_ = 0, bridges_ = 0, caps_ = 0, unions_ = 0, opened_pp_ = 0, opened_pw_ = 0;
  std::vector<std::vector<double>> cut_angle_;  // per sphere and cut, see add_cut
};

}  // namespace

TreatedBed treat_contacts(const Bed& bed, const SurfaceParams& p, DomainPlanes planes) {
  if (!planes.clip) return ContactTreatment(bed, p, planes).run();
  // Survey the whole bed's contacts, place the clip planes clear of them and of every sphere's
  // top and bottom, then treat the window.
  const double inf = std::numeric_limits<double>::infinity();
  ContactTreatment survey(bed, p, {-inf, inf, false}, {.record_extents = true});
  const TreatedBed whole = survey.run();
  const ClipPlacement placed = place_clip_planes(bed, p, planes, whole.radius, survey.extents());
  const ClipOpening* opening = placed.opening.contacts.empty() ? nullptr : &placed.opening;
  TreatedBed out =
      ContactTreatment(bed, p, placed.planes, {.surveyed = &survey.extents(), .opening = opening}).run();
  out.report["clip"] = placed.report;
  return out;
}

}  // namespace bedforge::meshing
