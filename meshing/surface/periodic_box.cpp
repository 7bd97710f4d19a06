#include "meshing/surface/periodic_box.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>

#include "core/error.hpp"
#include "meshing/surface/planar_cdt.hpp"
#include "meshing/surface/plane_cut.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/spaced_points.hpp"
#include "meshing/surface/stl_io.hpp"
#include "meshing/surface/surface_checks.hpp"
#include "meshing/surface/wall_mesh.hpp"

namespace bedforge::meshing {

bool is_fully_periodic_box(const Container& c) {
  const Periodicity per = c.periodicity();
  return dynamic_cast<const Box*>(&c) != nullptr && per.lx > 0.0 && per.ly > 0.0 && per.lz > 0.0;
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::array<const char*, 3> kLowerPatch{"x_min", "y_min", "inlet"}, kUpperPatch{"x_max", "y_max", "outlet"};

// The box's planes per axis: lower, upper, and the period between them (exactly upper - lower,
// so that a point on one plane moved by it lands on the other bit for bit).
struct Cell {
  Eigen::Vector3d lo, hi, period;
};

// A sphere as it is meshed: its image in the box after the shift, the planes it crosses.
struct Placed {
  Eigen::Vector3d c;
  double r = 0.0;
  std::array<int, 3> cross{0, 0, 0};             // -1: crosses the lower plane, +1 the upper, 0 none
  Eigen::Vector3d plane = Eigen::Vector3d::Zero();  // the crossed plane's coordinate per axis
  Eigen::Vector3d beyond = Eigen::Vector3d::Zero();  // the move of its part beyond that plane: +period below, -period above
  // +1 when q lies on the box's side of the plane crossed on `axis`, -1 beyond it.
  int side(const Eigen::Vector3d& q, int axis) const {
    return cross[axis] < 0 ? (q[axis] >= plane[axis] ? 1 : -1) : (q[axis] <= plane[axis] ? 1 : -1);
  }
};

// Part of the circle where a sphere meets the plane of `axis`, between two of the points where
// the box's edges pierce the sphere, or the whole circle.
struct Arc {
  int axis = 0;
  std::vector<Eigen::Vector3d> points;  // in order; the ends are edge points unless whole
  int first = -1, last = -1;            // the edge points at its ends (-1: a whole circle)
  std::array<int, 3> side{0, 0, 0};     // per other crossed axis: +1 on the box's side, -1 beyond
  bool whole() const { return first < 0; }
};

// Plane positions (in the bed's frame, along one axis of period L from `lo`) in the middle of the
// widest gaps between the spheres' ends, widest first, with half the gap (the clearance).
std::vector<std::pair<double, double>> plane_candidates(const std::vector<double>& centre, const std::vector<double>& r,
                                                        double lo, double L, std::size_t count) {
  std::vector<double> ends;
  for (std::size_t i = 0; i < centre.size(); ++i)
    for (double e : {centre[i] - r[i], centre[i] + r[i]}) ends.push_back(lo + (e - lo - L * std::floor((e - lo) / L)));
  if (ends.empty()) return {{lo, 0.5 * L}};
  std::sort(ends.begin(), ends.end());
  std::vector<std::pair<double, double>> gaps;  // (half width, middle)
  for (std::size_t k = 0; k < ends.size(); ++k) {
    const double next = k + 1 < ends.size() ? ends[k + 1] : ends[0] + L;
    gaps.emplace_back(0.5 * (next - ends[k]), 0.5 * (ends[k] + next));
  }
  std::sort(gaps.begin(), gaps.end(), [](const auto& u, const auto& v) { return u.first > v.first; });
  std::vector<std::pair<double, double>> out;
  for (std::size_t k = 0; k < std::min(count, gaps.size()); ++k) out.emplace_back(gaps[k].second, gaps[k].first);
  return out;
}

// The spheres placed in the box after moving the bed by `shift` (m).
std::vector<Placed> place(const Bed& bed, const std::vector<double>& radii, const Cell& cell, const Eigen::Vector3d& shift) {
  std::vector<Placed> out(bed.size());
  for (std::size_t i = 0; i < bed.size(); ++i) {
    Placed& s = out[i];
    s.r = radii[i];
    for (int a = 0; a < 3; ++a) {
      const double t = bed.centres[i][a] + shift[a] - cell.lo[a];
      s.c[a] = cell.lo[a] + (t - cell.period[a] * std::floor(t / cell.period[a]));
      if (s.c[a] - s.r < cell.lo[a]) s.cross[a] = -1, s.plane[a] = cell.lo[a], s.beyond[a] = cell.period[a];
      else if (s.c[a] + s.r > cell.hi[a]) s.cross[a] = 1, s.plane[a] = cell.hi[a], s.beyond[a] = -cell.period[a];
    }
  }
  return out;
}

// Distance from the sphere's centre to its crossed plane on `axis`.
double depth(const Placed& s, int a) { return std::abs(s.c[a] - s.plane[a]); }

// How near the placed spheres come to grazing an edge of the box, or -1 when one holds a corner.
double edge_clearance(const std::vector<Placed>& spheres) {
  double clearance = std::numeric_limits<double>::infinity();
  for (const Placed& s : spheres) {
    std::vector<int> crossed;
    for (int a = 0; a < 3; ++a)
      if (s.cross[a] != 0) crossed.push_back(a);
    for (std::size_t i = 0; i < crossed.size(); ++i)
      for (std::size_t j = i + 1; j < crossed.size(); ++j)
        clearance = std::min(clearance, std::abs(std::hypot(depth(s, crossed[i]), depth(s, crossed[j])) - s.r));
    if (crossed.size() == 3) {
      const double corner = std::hypot(depth(s, 0), depth(s, 1), depth(s, 2)) - s.r;
      if (corner <= 0.0) return -1.0;
      clearance = std::min(clearance, corner);
    }
  }
  return clearance;
}

// Points spaced by `spacing(t)` strictly between s0 and s1 (1D, m), about one per spacing.
std::vector<double> graded_between(double s0, double s1, const std::function<double(double)>& spacing, double finest) {
  const int samples = std::max(2, static_cast<int>(std::ceil((s1 - s0) / (0.25 * finest))) + 1);
  std::vector<double> t(samples), count(samples, 0.0);
  for (int k = 0; k < samples; ++k) t[k] = s0 + (s1 - s0) * k / (samples - 1);
  for (int k = 1; k < samples; ++k) count[k] = count[k - 1] + 0.5 * (t[k] - t[k - 1]) * (1.0 / spacing(t[k - 1]) + 1.0 / spacing(t[k]));
  const int parts = std::max(1, static_cast<int>(std::lround(count.back())));
  std::vector<double> out;
  for (int j = 1, k = 1; j < parts; ++j) {
    const double want = count.back() * j / parts;
    while (count[k] < want) ++k;
    const double f = (want - count[k - 1]) / (count[k] - count[k - 1]);
    out.push_back(t[k - 1] + f * (t[k] - t[k - 1]));
  }
  return out;
}

// A point of the plane of `axis` from its coordinate there and its two in-plane coordinates
// (u = axis + 1, v = axis + 2, cyclically).
Eigen::Vector3d on_plane(int axis, double at, double u, double v) {
  Eigen::Vector3d x;
  x[axis] = at, x[(axis + 1) % 3] = u, x[(axis + 2) % 3] = v;
  return x;
}

}  // namespace

void check_periodic_box(const Container& container, const SurfaceParams& p) {
  const Periodicity per = container.periodicity();
  if (!per.lateral()) return;
  if (!is_fully_periodic_box(container))
    throw InputError(fmt::format(
        "container.periodic_x = {}, periodic_y = {}, period_z_d {}: a box with periodic sides is meshed periodic on "
        "every side; allowed: periodic_x and periodic_y both true with container.period_z_d, or both false",
        per.lx > 0.0, per.ly > 0.0, per.lz > 0.0 ? "set" : "not set"));
  using Treatment = SurfaceParams::Treatment;
  if (p.treatment != Treatment::none && p.treatment != Treatment::shrink)
    throw InputError(fmt::format("contacts.treatment = \"{}\" in a box periodic on every side: no contact is joined "
                                 "across its sides yet; allowed: \"none\" or \"shrink\"",
                                 treatment_name(p.treatment)));
}

FluidSurface build_periodic_box_surface(const Bed& bed, const SurfaceParams& p) {
  using Treatment = SurfaceParams::Treatment;
  check_periodic_box(*bed.container, p);
  const auto& box = dynamic_cast<const Box&>(*bed.container);
  const Periodicity per = box.periodicity();
  const double d = reference_diameter(bed), edge = p.edge_length_d * d;
  const double fine = std::min(p.contact_edge_length_d * d, edge);
  Cell cell;
  cell.lo = Eigen::Vector3d(-0.5 * box.size_x(), -0.5 * box.size_y(), 0.0);
  cell.hi = Eigen::Vector3d(0.5 * box.size_x(), 0.5 * box.size_y(), per.lz);
  cell.period = cell.hi - cell.lo;
  const std::size_t n = bed.size();

  // 1. The treated radii, and the narrowest gap between spheres (over periodic images).
  std::vector<double> radii(n);
  for (std::size_t i = 0; i < n; ++i)
    radii[i] = 0.5 * bed.diameters[i] * (p.treatment == Treatment::shrink ? p.shrink_factor : 1.0);
  double narrowest = std::numeric_limits<double>::infinity();
  long touching = 0;
  std::pair<std::size_t, std::size_t> narrowest_pair{0, 0};
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double between = per.separation(bed.centres[i], bed.centres[j]).norm();
      if (between - 0.5 * (bed.diameters[i] + bed.diameters[j]) <= 1e-9 * d) ++touching;
      if (const double gap = between - radii[i] - radii[j]; gap < narrowest) narrowest = gap, narrowest_pair = {i, j};
    }
  if (!(narrowest > 0.0))
    throw InputError(fmt::format("contacts.treatment = \"{}\": particles {} and {} {} ({:.3g} d); a box periodic on "
                                 "every side takes spheres apart; allowed: \"shrink\" with contacts.shrink_factor "
                                 "small enough to part them",
                                 treatment_name(p.treatment), narrowest_pair.first, narrowest_pair.second,
                                 narrowest < 0.0 ? "overlap" : "touch", narrowest / d));

  // 2. The shift: per axis the planes in the widest gaps between the spheres' ends, the
  // combination that keeps farthest from the ends and from grazing the box's edges.
  constexpr std::size_t kCandidates = 6;
  std::array<std::vector<std::pair<double, double>>, 3> candidates;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> c(n);
    for (std::size_t i = 0; i < n; ++i) c[i] = bed.centres[i][a];
    candidates[a] = plane_candidates(c, radii, cell.lo[a], cell.period[a], kCandidates);
  }
  double best = -1.0;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (const auto& [px, cx] : candidates[0])
    for (const auto& [py, cy] : candidates[1])
      for (const auto& [pz, cz] : candidates[2]) {
        const Eigen::Vector3d s = cell.lo - Eigen::Vector3d(px, py, pz);
        const double clearance = std::min({cx, cy, cz, edge_clearance(place(bed, radii, cell, s))});
        if (clearance > best) best = clearance, shift = s;
      }
  if (!(best >= p.clip_clearance_d * d))
    throw InputError(fmt::format(
        "container: no position of the periodic box's sides keeps surface.clip_clearance_d = {} from every sphere's "
        "ends and edges{} (best {:.3g} d); allowed: a smaller surface.clip_clearance_d or another bed",
        p.clip_clearance_d, best < 0.0 ? " without a sphere holding a corner" : "", std::max(best, 0.0) / d));
  const std::vector<Placed> spheres = place(bed, radii, cell, shift);

  // 3. Where the box's edges pierce each sphere: two points per pair of crossed planes whose
  // edge passes through it, shared by the two circles.
  std::vector<Eigen::Vector3d> edge_points;
  std::vector<std::array<std::array<int, 2>, 3>> pierced(n);  // [sphere][third axis] -> two edge points or -1
  // Per edge family (the axis the edge runs along): the intervals inside spheres.
  std::array<std::vector<std::array<int, 2>>, 3> intervals;
  for (std::size_t i = 0; i < n; ++i) {
    const Placed& s = spheres[i];
    for (int w = 0; w < 3; ++w) {
      pierced[i][w] = {-1, -1};
      const int a = (w + 1) % 3, b = (w + 2) % 3;
      if (s.cross[a] == 0 || s.cross[b] == 0) continue;
      const double da = s.c[a] - s.plane[a], db = s.c[b] - s.plane[b], root2 = s.r * s.r - da * da - db * db;
      if (root2 <= 0.0) continue;
      const double root = std::sqrt(root2);
      for (int k = 0; k < 2; ++k) {
        Eigen::Vector3d x;
        x[a] = s.plane[a], x[b] = s.plane[b], x[w] = k == 0 ? s.c[w] - root : s.c[w] + root;
        pierced[i][w][k] = static_cast<int>(edge_points.size());
        edge_points.push_back(x);
      }
      intervals[w].push_back(pierced[i][w]);
    }
  }

  // 4. Each sphere's circles on its crossed planes, split at the edge points into arcs at the
  // contact edge's spacing.
  std::vector<std::vector<Arc>> arcs(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Placed& s = spheres[i];
    for (int a = 0; a < 3; ++a) {
      if (s.cross[a] == 0) continue;
      const int u = (a + 1) % 3, v = (a + 2) % 3;
      const double rho = std::sqrt(std::max(0.0, s.r * s.r - (s.c[a] - s.plane[a]) * (s.c[a] - s.plane[a])));
      auto at = [&](double theta) { return on_plane(a, s.plane[a], s.c[u] + rho * std::cos(theta), s.c[v] + rho * std::sin(theta)); };
      auto sides = [&](Arc& arc, const Eigen::Vector3d& q) {
        for (int b = 0; b < 3; ++b)
          if (b != a && s.cross[b] != 0) arc.side[b] = s.side(q, b);
      };
      std::vector<std::pair<double, int>> breaks;  // (angle, edge point)
      for (int w = 0; w < 3; ++w)
        if (w != a)
          for (int e : pierced[i][w])
            if (e >= 0) breaks.emplace_back(std::atan2(edge_points[e][v] - s.c[v], edge_points[e][u] - s.c[u]), e);
      std::sort(breaks.begin(), breaks.end());
      if (breaks.empty()) {
        Arc arc;
        arc.axis = a;
        const int count = ring_points(rho, fine);
        for (int j = 0; j < count; ++j) arc.points.push_back(at(2.0 * kPi * j / count));
        sides(arc, arc.points[0]);
        arcs[i].push_back(std::move(arc));
        continue;
      }
      for (std::size_t k = 0; k < breaks.size(); ++k) {
        const auto [t0, e0] = breaks[k];
        const auto [t1_, e1] = breaks[(k + 1) % breaks.size()];
        const double t1 = k + 1 < breaks.size() ? t1_ : t1_ + 2.0 * kPi;
        Arc arc;
        arc.axis = a, arc.first = e0, arc.last = e1;
        const int parts = std::max(1, static_cast<int>(std::ceil(rho * (t1 - t0) / fine)));
        arc.points.push_back(edge_points[e0]);
        for (int j = 1; j < parts; ++j) arc.points.push_back(at(t0 + (t1 - t0) * j / parts));
        arc.points.push_back(edge_points[e1]);
        sides(arc, at(0.5 * (t0 + t1)));
        arcs[i].push_back(std::move(arc));
      }
    }
  }

  // 5. Spacing: the narrow gaps' rule over the spheres and their images near the box, and on the
  // sides a grading from the circles' spacing up to the surface edge.
  std::vector<Eigen::Vector3d> near_centres;
  std::vector<double> near_radii;
  const double largest = n > 0 ? *std::max_element(radii.begin(), radii.end()) : 0.0;
  const double reach = std::max(p.cells_per_gap, 1.0) * edge + 2.0 * largest;
  for (std::size_t i = 0; i < n; ++i) near_centres.push_back(spheres[i].c), near_radii.push_back(spheres[i].r);
  for (std::size_t i = 0; i < n; ++i)
    for (int kx = -1; kx <= 1; ++kx)
      for (int ky = -1; ky <= 1; ++ky)
        for (int kz = -1; kz <= 1; ++kz) {
          if (kx == 0 && ky == 0 && kz == 0) continue;
          const Eigen::Vector3d c = spheres[i].c + Eigen::Vector3d(kx, ky, kz).cwiseProduct(cell.period);
          if (((c - cell.lo).array() > -reach).all() && ((cell.hi - c).array() > -reach).all())
            near_centres.push_back(c), near_radii.push_back(spheres[i].r);
        }
  const std::vector<char> kept(near_centres.size(), 1);
  const std::optional<GapSpacing> gaps = gap_spacing(p, d, near_centres, near_radii, kept, box);
  const std::optional<GapSpacing> clearance = facet_clearance(p, d, near_centres, near_radii, kept, box);
  const double grade = std::max(p.growth - 1.0, 1e-3), graded_reach = (edge - fine) / grade;

  // 6. The circles as they fall on each side (2D: the side's u and v), moved by the periods of
  // the other sides they lie beyond; and per side the grading field from their points, repeated
  // a period along u and v so that the field is periodic.
  struct OnSide {
    std::vector<Eigen::Vector2d> points;
    int sphere = 0, first = -1, last = -1;
    Eigen::Vector2d centre;
  };
  std::array<std::vector<OnSide>, 3> on_side;
  std::array<PointsByCell, 3> side_grid{PointsByCell(graded_reach), PointsByCell(graded_reach), PointsByCell(graded_reach)};
  std::array<std::vector<Eigen::Vector2d>, 3> side_points;
  for (std::size_t i = 0; i < n; ++i)
    for (const Arc& arc : arcs[i]) {
      const int a = arc.axis, u = (a + 1) % 3, v = (a + 2) % 3;
      const Placed& s = spheres[i];
      const double su = arc.side[u] < 0 ? s.beyond[u] : 0.0, sv = arc.side[v] < 0 ? s.beyond[v] : 0.0;
      OnSide o;
      o.sphere = static_cast<int>(i), o.first = arc.first, o.last = arc.last;
      o.centre = Eigen::Vector2d(s.c[u] + su, s.c[v] + sv);
      for (const auto& x : arc.points) o.points.emplace_back(x[u] + su, x[v] + sv);
      for (const auto& q : o.points)
        for (int ku = -1; ku <= 1; ++ku)
          for (int kv = -1; kv <= 1; ++kv) {
            const Eigen::Vector2d r = q + Eigen::Vector2d(ku * cell.period[u], kv * cell.period[v]);
            side_grid[a].add(Eigen::Vector3d(r.x(), r.y(), 0.0), static_cast<int>(side_points[a].size()));
            side_points[a].push_back(r);
          }
      on_side[a].push_back(std::move(o));
    }
  auto side_spacing = [&](int a, const Eigen::Vector3d& x) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const Eigen::Vector2d q(x[u], x[v]);
    double nearest = graded_reach;
    side_grid[a].near(Eigen::Vector3d(q.x(), q.y(), 0.0),
                      [&](int k) { nearest = std::min(nearest, (side_points[a][k] - q).norm()); });
    double h = std::min(edge, fine + grade * nearest);
    if (gaps) h = std::min(h, gaps->at(x, -1));
    return h;
  };

  // 7. The box's edges: per family (the axis w they run along), the points from the lower to
  // the upper corner, the edge points where spheres cover it, graded between; each segment
  // marked when it lies inside a sphere. Every side holding such an edge takes these points.
  struct EdgeRow {
    std::vector<double> t;
    std::vector<char> covered;  // segment k (t[k] to t[k + 1]) inside a sphere
  };
  std::array<EdgeRow, 3> rows;
  for (int w = 0; w < 3; ++w) {
    const int a = (w + 1) % 3, b = (w + 2) % 3;
    std::vector<std::array<double, 2>> inside;
    for (const auto& iv : intervals[w]) inside.push_back({edge_points[iv[0]][w], edge_points[iv[1]][w]});
    std::sort(inside.begin(), inside.end());
    auto spacing = [&](double t) {
      Eigen::Vector3d x;
      x[a] = cell.lo[a], x[b] = cell.lo[b], x[w] = t;
      return std::min(side_spacing(a, x), side_spacing(b, x));
    };
    EdgeRow& row = rows[w];
    double from = cell.lo[w];
    auto free_run = [&](double to) {
      row.t.push_back(from);
      for (double t : graded_between(from, to, spacing, fine)) row.covered.push_back(0), row.t.push_back(t);
      row.covered.push_back(0);
    };
    for (const auto& [t0, t1] : inside) {
      free_run(t0);
      row.t.push_back(t0), row.covered.push_back(1);
      from = t1;
    }
    free_run(cell.hi[w]);
    row.t.push_back(cell.hi[w]);
  }

  // 8. Each side: its outline walked anticlockwise (in u, v), leaving the edges where a disk
  // covers them along the disk's arc; whole circles inside are holes. Meshed once at the lower
  // plane, copied to the upper.
  FluidSurface out;
  TriangleMesh& f = out.fluid;
  long side_triangles = 0, side_regions = 0;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    using Key = std::pair<double, double>;
    std::vector<std::vector<Eigen::Vector2d>> runs;  // directed: the fluid on their left
    std::vector<std::pair<const OnSide*, Key>> holes_found;
    auto add_row = [&](const EdgeRow& row, bool ascending, const std::function<Eigen::Vector2d(double)>& at) {
      const std::size_t m = row.t.size();
      for (std::size_t k = 0; k + 1 < m; ++k) {
        const std::size_t s = ascending ? k : m - 2 - k;
        if (row.covered[s]) continue;
        runs.push_back(ascending ? std::vector<Eigen::Vector2d>{at(row.t[s]), at(row.t[s + 1])}
                                 : std::vector<Eigen::Vector2d>{at(row.t[s + 1]), at(row.t[s])});
      }
    };
    add_row(rows[u], true, [&](double t) { return Eigen::Vector2d(t, cell.lo[v]); });
    add_row(rows[v], true, [&](double t) { return Eigen::Vector2d(cell.hi[u], t); });
    add_row(rows[u], false, [&](double t) { return Eigen::Vector2d(t, cell.hi[v]); });
    add_row(rows[v], false, [&](double t) { return Eigen::Vector2d(cell.lo[u], t); });
    std::vector<const OnSide*> whole;
    for (const OnSide& o : on_side[a]) {
      if (o.first < 0) {
        whole.push_back(&o);
        continue;
      }
      std::vector<Eigen::Vector2d> run = o.points;
      const std::size_t mid = run.size() / 2 - (run.size() > 2 ? 0 : 1);
      const Eigen::Vector2d dir = run[mid + 1] - run[mid], to = o.centre - run[mid];
      if (dir.x() * to.y() - dir.y() * to.x() > 0.0) std::reverse(run.begin(), run.end());  // the disk on the right
      runs.push_back(std::move(run));
    }
    std::map<Key, std::size_t> starting;
    for (std::size_t k = 0; k < runs.size(); ++k)
      if (!starting.emplace(Key(runs[k][0].x(), runs[k][0].y()), k).second)
        throw std::runtime_error(fmt::format("periodic box: the side at {} = {:.6g} m has two outline runs from ({:.6g}, "
                                             "{:.6g}); please report it with the bed",
                                             "xyz"[a], cell.lo[a], runs[k][0].x(), runs[k][0].y()));
    std::vector<char> used(runs.size(), 0);
    std::vector<std::vector<Eigen::Vector2d>> outlines;
    for (std::size_t k0 = 0; k0 < runs.size(); ++k0) {
      if (used[k0]) continue;
      std::vector<Eigen::Vector2d> loop;
      for (std::size_t k = k0; !used[k];) {
        used[k] = 1;
        loop.insert(loop.end(), runs[k].begin(), runs[k].end() - 1);
        const auto it = starting.find(Key(runs[k].back().x(), runs[k].back().y()));
        if (it == starting.end())
          throw std::runtime_error(fmt::format("periodic box: the side at {} = {:.6g} m has an outline run ending at "
                                               "({:.6g}, {:.6g}) that nothing continues; please report it with the bed",
                                               "xyz"[a], cell.lo[a], runs[k].back().x(), runs[k].back().y()));
        k = it->second;
      }
      outlines.push_back(std::move(loop));
    }
    Frame frame;
    frame.origin = Eigen::Vector3d::Zero(), frame.origin[a] = cell.lo[a];
    frame.u = Eigen::Vector3d::Unit(u), frame.v = Eigen::Vector3d::Unit(v), frame.w = Eigen::Vector3d::Unit(a);
    SpacingField field{[&, a](const Eigen::Vector3d& x) { return side_spacing(a, x); }, fine};
    for (const auto& outline : outlines) {
      std::vector<Eigen::Vector3d> boundary;
      for (const auto& q : outline) boundary.push_back(on_plane(a, cell.lo[a], q.x(), q.y()));
      std::vector<WallHole> holes;
      for (const OnSide* o : whole)
        if (inside_polygon(outline, o->points[0])) {
          WallHole h;
          for (const auto& q : o->points) h.loop.push_back(on_plane(a, cell.lo[a], q.x(), q.y()));
          h.spacing = fine, h.particle = o->sphere;
          holes.push_back(std::move(h));
        }
      WallMesh m;
      try {
        m = plane_mesh(frame, {boundary}, edge, holes, p.growth, false, kLowerPatch[a], field);
      } catch (const CutConflict& e) {
        throw InputError(fmt::format("the periodic box's side at {} = {:.6g} m: {}; allowed: another "
                                     "surface.contact_edge_length_d or bed",
                                     "xyz"[a], cell.lo[a], e.what()));
      }
      TriangleMesh upper = m.outside;
      for (auto& x : upper.points) x[a] = cell.hi[a];
      for (auto& t : upper.triangles) std::swap(t[1], t[2]);
      upper.patches = {kUpperPatch[a]};
      f.append(m.outside);
      f.append(upper);
      side_triangles += static_cast<long>(m.outside.triangles.size());
      ++side_regions;
    }
  }

  // 9. The spheres: each crossing sphere split into its parts, one per side of its crossed
  // planes that its arcs bound, each meshed within them and moved by the periods of the planes
  // it lies beyond.
  std::vector<std::vector<TriangleMesh>> parts(n);
  std::vector<std::string> failure(n);
  std::vector<double> chordal(n, 0.0), pushed(n, 0.0);
  long spheres_cut = 0;
  for (const Placed& s : spheres) spheres_cut += (s.cross[0] != 0 || s.cross[1] != 0 || s.cross[2] != 0) ? 1 : 0;
#pragma omp parallel for schedule(dynamic, 4)
  for (std::size_t i = 0; i < n; ++i) {
    const Placed& s = spheres[i];
    const SpacingField field = gaps ? SpacingField{[&gaps, i](const Eigen::Vector3d& q) { return gaps->at(q, static_cast<int>(i)); },
                                                   gaps->finest()}
                                    : SpacingField{};
    const auto gap_to_others = [&clearance, i](const Eigen::Vector3d& x) { return clearance->gap(x, static_cast<int>(i)); };
    std::vector<int> crossed;
    for (int a = 0; a < 3; ++a)
      if (s.cross[a] != 0) crossed.push_back(a);
    int mask = 0;
    try {
      for (; mask < (1 << crossed.size()); ++mask) {
        std::array<int, 3> sigma{0, 0, 0};
        Eigen::Vector3d move = Eigen::Vector3d::Zero();
        for (std::size_t k = 0; k < crossed.size(); ++k) {
          sigma[crossed[k]] = (mask >> k & 1) ? -1 : 1;
          if (sigma[crossed[k]] < 0) move[crossed[k]] = s.beyond[crossed[k]];
        }
        // Its arcs: those whose sides match the part's on every other crossed plane.
        std::vector<const Arc*> bounding;
        for (const Arc& arc : arcs[i]) {
          bool match = true;
          for (int b : crossed)
            if (b != arc.axis && arc.side[b] != sigma[b]) match = false;
          if (match) bounding.push_back(&arc);
        }
        if (bounding.empty()) continue;
        auto removed = [&s, sigma, crossed](const Eigen::Vector3d& q) {
          for (int b : crossed)
            if (s.side(q, b) != sigma[b]) return true;
          return false;
        };
        // Loops: whole circles alone, arcs chained at their shared edge points.
        std::vector<SphereCut> cuts;
        std::vector<char> used(bounding.size(), 0);
        for (std::size_t k0 = 0; k0 < bounding.size(); ++k0) {
          if (used[k0]) continue;
          SphereCut cut;
          Eigen::Vector3d axis = Eigen::Vector3d::Zero();
          auto take = [&](const Arc& arc) { axis[arc.axis] = sigma[arc.axis] * s.cross[arc.axis]; };
          used[k0] = 1;
          take(*bounding[k0]);
          cut.loop = bounding[k0]->points;
          if (!bounding[k0]->whole()) {
            const int start = bounding[k0]->first;
            for (int end = bounding[k0]->last; end != start;) {
              std::size_t next = bounding.size();
              for (std::size_t k = 0; k < bounding.size() && next == bounding.size(); ++k)
                if (!used[k] && (bounding[k]->first == end || bounding[k]->last == end)) next = k;
              if (next == bounding.size())
                throw CutConflict("its arcs do not close into a loop at the box's edges");
              used[next] = 1;
              const Arc& arc = *bounding[next];
              take(arc);
              if (arc.first == end) {
                cut.loop.insert(cut.loop.end(), arc.points.begin() + 1, arc.points.end());
                end = arc.last;
              } else {
                cut.loop.insert(cut.loop.end(), arc.points.rbegin() + 1, arc.points.rend());
                end = arc.first;
              }
            }
            cut.loop.pop_back();  // the start again
          }
          cut.spacing = fine;
          cut.axis = axis.normalized();
          cut.removed = removed;
          cut.fluid_ends = true;
          // The faces spanning the removed part lie in one of the planes (their coordinate exact).
          cut.spans = [crossed, plane = s.plane](const Eigen::Vector3d& x, const Eigen::Vector3d& y, const Eigen::Vector3d& z) {
            return std::any_of(crossed.begin(), crossed.end(),
                               [&](int b) { return x[b] == plane[b] && y[b] == plane[b] && z[b] == plane[b]; });
          };
          cuts.push_back(std::move(cut));
        }
        TriangleMesh part = sphere_mesh(s.c, s.r, cuts, edge, p.growth, true, "particles", field);
        chordal[i] = std::max(chordal[i], chordal_deviation(part, s.c, s.r));
        if (clearance) pushed[i] = std::max(pushed[i], match_sphere_volume(part, s.c, s.r, cuts, gap_to_others));
        for (auto& x : part.points) x += move;
        parts[i].push_back(std::move(part));
      }
      if (crossed.empty()) {
        parts[i].push_back(sphere_mesh(s.c, s.r, {}, edge, p.growth, true, "particles", field));
        chordal[i] = chordal_deviation(parts[i].back(), s.c, s.r);
        if (clearance) pushed[i] = match_sphere_volume(parts[i].back(), s.c, s.r, {}, gap_to_others);
      }
    } catch (const CutConflict& e) {
      std::string where;
      for (std::size_t k = 0; k < crossed.size(); ++k)
        where += fmt::format("{}{} {}", k > 0 ? ", " : "", (mask >> k & 1) ? "beyond" : "within", "xyz"[crossed[k]]);
      failure[i] = fmt::format("sphere {} (cut by the periodic box's sides, its part {}): {}; allowed: a shorter "
                               "surface.contact_edge_length_d or another bed",
                               i, where, e.what());
    }
  }
  for (const auto& message : failure)
    if (!message.empty()) throw InputError(message);
  for (auto& sphere_parts : parts)
    for (TriangleMesh& m : sphere_parts) {
      for (auto& t : m.triangles) std::swap(t[1], t[2]);
      f.append(m);
      m = TriangleMesh();
    }
  f.weld();
  round_to_ascii_stl(f);
  if (const SurfaceCheck closed = check_surface(f, SelfIntersectionTest::skip); !closed.closed || !closed.manifold)
    throw std::runtime_error(fmt::format("periodic box: the sides and the spheres' parts do not close ({} edges "
                                         "unmatched, first at{}); please report it with the bed",
                                         closed.defects.size(), describe_defects(closed)));

  // 10. What the surface stage reports.
  double solid = 0.0, change = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r0 = 0.5 * bed.diameters[i];
    solid += 4.0 / 3.0 * kPi * radii[i] * radii[i] * radii[i];
    change += 4.0 / 3.0 * kPi * (radii[i] * radii[i] * radii[i] - r0 * r0 * r0);
  }
  const double domain = cell.period.prod();
  out.exact_volume_m3 = domain - solid;
  nlohmann::json& j = out.report;
  j["parameters"] = to_json(p);
  j["contacts_treated"] = {{"particle_particle", p.treatment == Treatment::shrink ? touching : 0}, {"particle_wall", 0}};
  j["smallest_gap_d"] = {{"particle_particle", narrowest / d}};
  j["solid_volume_exact_m3"] = solid;
  j["solid_volume_change_m3"] = change;
  j["fluid_volume_exact_m3"] = out.exact_volume_m3;
  j["void_fraction_bed_section_change"] = -change / domain;
  j["chordal_deviation_d"] = (n > 0 ? *std::max_element(chordal.begin(), chordal.end()) : 0.0) / d;
  j["sphere_vertices_moved_out_d"] = (n > 0 ? *std::max_element(pushed.begin(), pushed.end()) : 0.0) / d;
  j["domain_m"] = {{"inlet_z", cell.lo.z()}, {"outlet_z", cell.hi.z()}};
  j["periodic_box"] = {{"shift_m", {shift.x(), shift.y(), shift.z()}},
                       {"clearance_d", best / d},
                       {"spheres_cut", spheres_cut},
                       {"edge_points", edge_points.size()},
                       {"side_regions", side_regions},
                       {"side_triangles", side_triangles}};
  finish_cut_surface(out, d);
  return out;
}

}  // namespace bedforge::meshing
