#pragma once
// The contact treatment's working parts, for the files that make it up and nothing else:
// contacts.cpp (the walk over the bed and its bookkeeping, enlarge's growing), contact_pairs.cpp
// (two spheres: cap, union, bridge) and contact_walls.cpp (a sphere and a wall or clip plane).
// The public entry is treat_contacts (contacts.hpp).
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <array>
#include <cstddef>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/neighbour_list.hpp"
#include "core/intersection_volumes.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/contacts.hpp"

namespace bedforge::meshing::contact_parts {

constexpr double kPi = std::numbers::pi;
constexpr double kContact = 1e-4;  // a gap below this (in d) is a contact, as in the packers

// Volume and curved area of the cap of height H cut from a sphere of radius r.
inline double cap_volume(double r, double H) { return kPi * H * H * (3.0 * r - H) / 3.0; }
inline double cap_area(double r, double H) { return 2.0 * kPi * r * H; }

// Distance from point q to the segment [a, b].
inline double segment_distance(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
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

// The walls of a cylinder, annulus or walled box; InputError for a periodic box or another container.
std::vector<Wall> walls_of(const Container& c);

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
  // `between` (z1, z2; m): also measure the treated solid between those heights
  // (TreatedBed::solid_volume_between_m3), as exactly as the whole.
  ContactTreatment(const Bed& bed, const SurfaceParams& p, DomainPlanes planes, ClipContext clip = {},
                   std::optional<std::array<double, 2>> between = std::nullopt);
  TreatedBed run();
  const ContactExtents& extents() const { return extents_; }

 private:
  using Treatment = SurfaceParams::Treatment;

  // contacts.cpp
  // Enlarging leaves the pairs that were just out of its reach a sliver of a gap (1e-6 d at
  // N = 1e4), which no volume mesh resolves, and those just within it a joint so thin that the
  // fluid around it is a wedge of a fraction of a degree (0.53 degrees at a = 5, N = 1000,
  // where no tetrahedron met the gate). So a sphere left nearer than `enlarge_join_gap_d` to
  // another sphere or to a wall, or overlapping it by less than half what the enlargement gives
  // spheres that touched (their radii x (factor - 1)), is grown further to overlap it by that
  // whole amount, and joined like the others. A curved wall's facets lie inside it by up to
  // their sagitta: there the reach is at least twice that. Growing can bring a sphere near a
  // third one, so this repeats until no such gap or joint is left.
  void grow_to_join();
  static constexpr int kJoinRounds = 20;
  // Gap below which a contact is treated (pairs and walls share the tolerance of their treatment).
  double treat_below(Treatment t) const;
  // `wall`: the wall of the gap, null for a pair's.
  void gap_left(double gap, const Wall* wall, const std::string& what);
  // `angle`: the largest angle from the cut's axis to its loop, seen from the centre.
  void add_cut(std::size_t i, SphereCut cut, const std::string& name, double angle);
  long long key(std::size_t i, std::size_t j) const { return contact_key(i, j, bed_.size()); }
  // How much geometry there is before a contact is treated, so its extent can be taken after.
  struct Marks {
    std::size_t cuts_i, cuts_j, parts;
    std::vector<std::size_t> holes;
  };
  Marks mark(std::size_t i, std::size_t j) const;
  // The z extent of what the contact (i, j) added since `m` (the cut caps included), widened by `pad`.
  void record(long long k, const Marks& m, std::size_t i, std::size_t j, double pad);
  // The counts a contact adds (treated pairs and walls, bridges, caps, unions), and, with heights
  // measured, those of contact k (recorded) that reach between them, since `before`.
  using Counts = std::array<long, 5>;
  Counts counts() const { return {treated_pp_, treated_pw_, bridges_, caps_, unions_}; }
  void count_between(long long k, const Counts& before);
  // With clip planes: true when the contact (as surveyed) lies wholly beyond them, so is left
  // out; InputError when it crosses one (the planes were placed clear of every contact).
  bool beyond_planes(long long k, const std::string& who) const;
  // Contact k (`wall`: its wall, null for a pair) when it is opened at a clip plane: its gap is
  // left as it is (nothing to do when a sphere of it is left out); returns false for any other
  // contact. InputError when shrinking did not open it (an overlap deeper than the shrink).
  bool open(long long k, const std::string& who, double gap, bool kept, const Wall* wall);
  // A planar cut of sphere i at distance h along axis a (unit), its loop of n vertices on the
  // circle of radius rho (given, so a bridge's loop is exactly its tube's) about `at` (default
  // c + h a), its rings jittered by `jitter` (SphereCut); returns the loop's frame.
  Frame plane_cut(std::size_t i, const Eigen::Vector3d& a, double h, double rho, int n, double jitter,
                  const std::string& name, std::optional<Eigen::Vector3d> at = std::nullopt, double turn = 0.0);
  // The cuts on one sphere must not overlap: the angle between their axes must exceed the sum
  // of their angular radii.
  void check_cuts(std::size_t i);
  void wedge(double angle) { min_wedge_ = std::min(min_wedge_, angle); }
  // Of the solid of revolution about the axis from `c` along `a` (unit), radius(t) from t0 to t1,
  // the part between the heights measured (`between`; 0 without them).
  double between(const Eigen::Vector3d& c, const Eigen::Vector3d& a, double t0, double t1,
                 const std::function<double(double)>& radius) const;
  // The cap of the sphere about `c` of radius r beyond distance h along a, between them.
  double cap_between(const Eigen::Vector3d& c, double r, const Eigen::Vector3d& a, double h) const;

  // contact_pairs.cpp
  // Spheres i and j: a contact closer than the treatment's gap is capped, joined or bridged
  // (cut_i, cut_j: the distances from each centre to its cut plane along the line of centres);
  // any other is left as the gap it is.
  void pair(std::size_t i, std::size_t j, const NeighbourList& nl);

  // contact_walls.cpp
  // Sphere i and wall w, as pair() with the wall's own treatment.
  void wall(std::size_t i, const Wall& w, const NeighbourList& nl);
  // Sphere i crossing wall w: its mesh stops on the curve where they meet, and the wall gets a hole there.
  void wall_union(std::size_t i, const Wall& w, const Eigen::Vector3d& a);
  // Sphere i's last cut is where it crosses a wall or clip plane: the loop is a hole there, and
  // the fluid's wedge between the sphere and that surface (normal `into_fluid` at the loop) is measured.
  void open_hole(std::size_t i, std::vector<WallHole>& holes, const Eigen::Vector3d& into_fluid);
  // Sphere i crossing a plane at distance h along a (unit, into the part removed): cut on the
  // exact circle (about `at` when given, so its loop lies exactly in the plane), a hole in the plane.
  void cross_plane(std::size_t i, const Eigen::Vector3d& a, double h, const std::string& name,
                   std::vector<WallHole>& holes, std::optional<Eigen::Vector3d> at);
  // Spheres must stay clear of the inlet and outlet planes, or are cut by them when they clip.
  void ends(std::size_t i);
  // Sphere i cut by the inlet (outlet) clip plane: its loop, exactly in the plane, is a hole in
  // that patch. The untreated reference loses the same cap of the untreated sphere.
  void clip(std::size_t i, bool outlet);

  const Bed& bed_;
  const SurfaceParams& p_;
  DomainPlanes planes_;
  ClipContext clip_;
  std::vector<Wall> walls_;
  ContactExtents extents_;
  double d_ = 0.0, edge_c_ = 0.0, scale_ = 1.0;
  TreatedBed out_;
  double volume_ = 0.0, area_ = 0.0, volume0_ = 0.0, area0_ = 0.0;
  long treated_pp_ = 0, treated_pw_ = 0, bridges_ = 0, caps_ = 0, unions_ = 0, opened_pp_ = 0, opened_pw_ = 0;
  std::optional<std::array<double, 2>> between_;
  double between_volume_ = 0.0, between_volume0_ = 0.0;  // treated and untreated, between the heights
  Counts between_counts_{};
  long grown_to_wall_ = 0, grown_to_sphere_ = 0;  // enlarged spheres grown further to join a wall, pairs grown to join
  double min_pair_gap_ = std::numeric_limits<double>::infinity(), min_wall_gap_ = min_pair_gap_, min_gap_ = min_pair_gap_;
  double min_concave_wall_gap_ = min_pair_gap_;
  double min_wedge_ = std::numeric_limits<double>::infinity();
  std::string gap_error_;
  std::vector<std::vector<double>> cut_angle_;  // per sphere and cut, see add_cut
};

}  // namespace bedforge::meshing::contact_parts
