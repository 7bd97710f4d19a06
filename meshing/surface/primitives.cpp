#include "meshing/surface/primitives.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Extreme_points_traits_adapter_3.h>
#include <CGAL/convex_hull_3.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "core/edge_key.hpp"
#include "core/random.hpp"
#include "meshing/surface/planar_cdt.hpp"
#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

// The loop of `cut` moved away from its axis by the arc `offset` on the sphere (c, r), then
// resampled at `spacing` (starting half a step on when `stagger`).
std::vector<Eigen::Vector3d> offset_loop(const SphereCut& cut, const Eigen::Vector3d& c, double r, double offset,
                                         double spacing, bool stagger) {
  std::vector<Eigen::Vector3d> moved;
  for (const auto& p : cut.loop) {
    const Eigen::Vector3d q = (p - c) / r;
    const double along = std::clamp(q.dot(cut.axis), -1.0, 1.0);
    Eigen::Vector3d e = q - along * cut.axis;
    if (e.norm() < 1e-12) continue;
    e.normalize();
    const double beta = std::acos(along) + offset / r;
    if (beta >= std::numbers::pi) return {};
    moved.push_back(c + r * (std::cos(beta) * cut.axis + std::sin(beta) * e));
  }
  if (moved.size() < 3) return {};
  std::vector<Eigen::Vector3d> out = resample_loop(moved, spacing, stagger);
  for (auto& p : out) p = c + r * (p - c).normalized();
  return out;
}

// Where four or more hull points are coplanar (cocircular, on a sphere) the hull may split the
// flat facet along either diagonal, and CGAL's choice follows the memory addresses of its
// faces, which differ between threads and runs. Each flat facet is therefore triangulated
// again as a fan from its lowest-numbered vertex, so the mesh depends on the points alone.
// `faces`: hull triangles (indices into `p`, consistently oriented), changed in place.
void canonical_flat_facets(std::vector<std::array<int, 3>>& faces, const std::vector<Kernel::Point_3>& p) {
  const int nf = static_cast<int>(faces.size()), nv = static_cast<int>(p.size());
  // Directed edges a -> b and their faces, grouped by a (a hull vertex has about six).
  std::vector<int> first(nv + 1, 0);
  for (const auto& t : faces)
    for (int v : t) ++first[v + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<std::pair<int, int>> out_edges(first[nv]);  // (b, face) of each a -> b
  std::vector<int> fill(first.begin(), first.end() - 1);
  for (int f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e) out_edges[fill[faces[f][e]]++] = {faces[f][(e + 1) % 3], f};
  auto face_across = [&](int a, int b) {  // the face holding edge b -> a
    for (int k = first[b]; k < first[b + 1]; ++k)
      if (out_edges[k].first == a) return out_edges[k].second;
    return -1;
  };
  // Flat facets: faces joined across edges where the neighbour's far vertex is coplanar.
  std::vector<int> group(nf);
  std::iota(group.begin(), group.end(), 0);
  auto root = [&group](int f) {
    while (group[f] != f) f = group[f] = group[group[f]];
    return f;
  };
  bool flat = false;
  for (int f = 0; f < nf; ++f)
    for (int e = 0; e < 3; ++e) {
      const int a = faces[f][e], b = faces[f][(e + 1) % 3], g = face_across(a, b);
      if (g < 0 || root(g) == root(f)) continue;
      const int far = faces[g][0] + faces[g][1] + faces[g][2] - a - b;
      if (CGAL::orientation(p[faces[f][0]], p[faces[f][1]], p[faces[f][2]], p[far]) != CGAL::COPLANAR) continue;
      group[root(g)] = root(f);
      flat = true;
    }
  if (!flat) return;
  // Each facet's boundary (its directed edges whose reverse lies outside it), walked from the
  // lowest vertex, becomes a fan.
  std::vector<int> order(nf);
  std::iota(order.begin(), order.end(), 0);
  for (int f = 0; f < nf; ++f) group[f] = root(f);
  std::stable_sort(order.begin(), order.end(), [&](int f, int g) { return group[f] < group[g]; });
  std::vector<std::array<int, 3>> out;
  std::vector<std::pair<int, int>> boundary;  // a -> b, sorted by a
  for (std::size_t first_face = 0, last; first_face < order.size(); first_face = last) {
    const int r = group[order[first_face]];
    for (last = first_face; last < order.size() && group[order[last]] == r; ++last) {}
    if (last - first_face == 1) {
      out.push_back(faces[order[first_face]]);
      continue;
    }
    boundary.clear();
    for (std::size_t k = first_face; k < last; ++k)
      for (int e = 0; e < 3; ++e) {
        const int a = faces[order[k]][e], b = faces[order[k]][(e + 1) % 3], g = face_across(a, b);
        if (g < 0 || group[g] != r) boundary.emplace_back(a, b);
      }
    std::sort(boundary.begin(), boundary.end());
    auto next = [&](int v) { return std::lower_bound(boundary.begin(), boundary.end(), std::make_pair(v, -1))->second; };
    const int v0 = boundary.front().first;
    for (int v = next(v0); next(v) != v0; v = next(v)) out.push_back({v0, v, next(v)});
  }
  faces = std::move(out);
}

// Adds the points p[first..] one by one to `faces`, a consistently oriented triangulation of the
// convex hull of the points before them: the faces a new point sees are replaced by a fan from it
// to their horizon. `seeds`: for each new point, a face (in the orientation of `faces`) likely
// to see it; `inside`: a point inside the hull. False, with `faces` unusable, when a point sees
// no face (it lies on the hull's boundary), for the caller to take the hull afresh.
bool insert_into_hull(std::vector<std::array<int, 3>>& faces, const std::vector<Kernel::Point_3>& p, std::size_t first,
                      const std::vector<std::array<int, 3>>& seeds, const Kernel::Point_3& inside) {
  auto directed = [](int a, int b) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 | static_cast<std::uint32_t>(b); };
  std::unordered_map<std::uint64_t, int> face_of;  // directed edge -> the face holding it
  face_of.reserve(3 * faces.size() + 6 * (p.size() - first) + 16);
  std::vector<char> alive(faces.size(), 1);
  for (int f = 0; f < static_cast<int>(faces.size()); ++f)
    for (int e = 0; e < 3; ++e) face_of[directed(faces[f][e], faces[f][(e + 1) % 3])] = f;
  const CGAL::Orientation in = CGAL::orientation(p[faces[0][0]], p[faces[0][1]], p[faces[0][2]], inside);
  std::vector<int> visible, stack;
  std::vector<std::pair<int, int>> horizon;
  std::vector<char> seen;
  for (std::size_t q = first; q < p.size(); ++q) {
    auto sees = [&](int f) {
      return alive[f] && CGAL::orientation(p[faces[f][0]], p[faces[f][1]], p[faces[f][2]], p[q]) == -in;
    };
    // A face that sees q: the seed, a face now holding the seed's first edge, or any.
    const std::array<int, 3>& s = seeds[q - first];
    int start = -1;
    if (const auto it = face_of.find(directed(s[0], s[1])); it != face_of.end() && sees(it->second)) start = it->second;
    for (int f = 0; start < 0 && f < static_cast<int>(faces.size()); ++f)
      if (sees(f)) start = f;
    if (start < 0) return false;
    // The faces that see q (a connected set), and the edges between them and the others.
    seen.assign(faces.size(), 0);
    visible.clear();
    horizon.clear();
    stack = {start};
    seen[start] = 1;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      visible.push_back(f);
      for (int e = 0; e < 3; ++e) {
        const int a = faces[f][e], b = faces[f][(e + 1) % 3], g = face_of.at(directed(b, a));
        if (seen[g]) continue;
        if (sees(g)) {
          seen[g] = 1;
          stack.push_back(g);
        } else {
          horizon.emplace_back(a, b);
        }
      }
    }
    for (int f : visible) {
      alive[f] = 0;
      for (int e = 0; e < 3; ++e) face_of.erase(directed(faces[f][e], faces[f][(e + 1) % 3]));
    }
    for (const auto& [a, b] : horizon) {
      faces.push_back({a, b, static_cast<int>(q)});
      alive.push_back(1);
      const int f = static_cast<int>(faces.size()) - 1;
      for (int e = 0; e < 3; ++e) face_of[directed(faces[f][e], faces[f][(e + 1) % 3])] = f;
    }
  }
  std::size_t kept = 0;
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (alive[f]) faces[kept++] = faces[f];
  faces.resize(kept);
  return true;
}

}  // namespace

Frame Frame::along(const Eigen::Vector3d& origin, const Eigen::Vector3d& axis) {
  Frame f;
  f.origin = origin;
  f.w = axis.normalized();
  if (f.w == Eigen::Vector3d::UnitZ()) return f;
  const Eigen::Vector3d helper = std::abs(f.w.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  f.u = (helper - helper.dot(f.w) * f.w).normalized();
  f.v = f.w.cross(f.u);
  return f;
}

Frame Frame::turned(double angle) const {
  Frame f = *this;
  f.u = std::cos(angle) * u + std::sin(angle) * v;
  f.v = w.cross(f.u);
  return f;
}

Eigen::Vector3d on_circle(double R, int j, int n, bool stagger, double z) {
  const double theta = (j + (stagger ? 0.5 : 0.0)) * (2.0 * std::numbers::pi / n);
  return {R * std::cos(theta), R * std::sin(theta), z};
}

int ring_points(double R, double edge) {
  return std::max(8, static_cast<int>(std::ceil(2.0 * std::numbers::pi * R / edge)));
}

double ring_sagitta(double R, double edge) { return R * (1.0 - std::cos(std::numbers::pi / ring_points(R, edge))); }

double ring_edge_for_sagitta(double R, double sagitta) {
  if (sagitta >= R * (1.0 - std::cos(std::numbers::pi / 8))) return HUGE_VAL;
  const double points = std::ceil(std::numbers::pi / std::acos(1.0 - sagitta / R));
  return 2.0 * std::numbers::pi * R / points * (1.0 + 1e-12);  // so that ring_points gives `points`
}

std::vector<Eigen::Vector3d> circle_loop(const Frame& f, double rho, int n) {
  std::vector<Eigen::Vector3d> loop;
  for (int j = 0; j < n; ++j) loop.push_back(f.to_world(on_circle(rho, j, n, false, 0.0)));
  return loop;
}

TriangleMesh sphere_mesh(const Eigen::Vector3d& c, double r, const std::vector<SphereCut>& cuts, double edge,
                         double growth, bool outward, const std::string& patch, const SpacingField& field) {
  auto lattice_count = [&](double spacing) {
    return static_cast<int>(std::ceil(4.0 * std::numbers::pi * r * r / (spacing * spacing * std::sqrt(3.0) / 2.0)));
  };
  const int n_lattice = std::max(48, lattice_count(edge));
  const double h = std::min(edge, std::sqrt(4.0 * std::numbers::pi * r * r / (n_lattice * std::sqrt(3.0) / 2.0)));
  SpacedPoints pts(h);
  auto is_removed = [&](const Eigen::Vector3d& p) {
    for (const auto& cut : cuts)
      if (cut.removed(p)) return true;
    return false;
  };
  // 1. The loops, exactly as given; owner[v] = the cut whose loop v is on.
  std::vector<int> owner;
  for (std::size_t k = 0; k < cuts.size(); ++k)
    for (const auto& p : cuts[k].loop) {
      pts.add(p, std::min(cuts[k].spacing, h));
      owner.push_back(static_cast<int>(k));
    }
  // 2. The field's seeds, then rings graded from each loop's spacing to h.
  for (const auto& [p, s] : field.seeds_finest_first())
    if (!is_removed(p) && pts.fits(p, s)) pts.add(p, s), owner.push_back(-1);
  std::vector<double> spacing;
  for (const auto& cut : cuts) spacing.push_back(cut.spacing);
  auto wanted = [&](const Eigen::Vector3d& p, double s) { return field ? std::min(s, field.at(p)) : s; };
  // Each ring point moves at random along the sphere by up to its cut's jitter / 2 of its
  // spacing (see kBreakCocircular).
  Rng nudge(1);
  graded_rings(spacing, h, growth, [&](std::size_t k, int ring, double offset, double next) {
    for (Eigen::Vector3d p : offset_loop(cuts[k], c, r, offset, next, ring % 2 == 1)) {
      p += cuts[k].jitter * next * Eigen::Vector3d(nudge.uniform() - 0.5, nudge.uniform() - 0.5, nudge.uniform() - 0.5);
      p = c + r * (p - c).normalized();
      const double s = wanted(p, next);
      if (!is_removed(p) && pts.fits(p, s)) pts.add(p, s), owner.push_back(-1);
    }
  });
  // 3. The Fibonacci lattice: of the field's finest spacing where it asks for less than h
  // (finest first, so the coarser vertices grade away from the finer), then of spacing h.
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  auto lattice = [&](int count, int k) {
    const double z = 1.0 - (2.0 * k + 1.0) / count, rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Eigen::Vector3d(c + r * Eigen::Vector3d(rho * std::cos(k * golden), rho * std::sin(k * golden), z));
  };
  if (field && field.finest < h) {
    const int n_fine = lattice_count(field.finest);
    offer_finest_first<Eigen::Vector3d>(
        field, h,
        [&](const auto& visit) {
          for (int k = 0; k < n_fine; ++k) visit(lattice(n_fine, k));
        },
        [](const Eigen::Vector3d& p) { return p; },
        [&](const Eigen::Vector3d& p, double s) {
          if (!is_removed(p) && pts.fits(p, s)) pts.add(p, s), owner.push_back(-1);
        });
  }
  for (int k = 0; k < n_lattice; ++k) {
    const Eigen::Vector3d p = lattice(n_lattice, k);
    const double s = wanted(p, h);
    if (!is_removed(p) && pts.fits(p, s)) pts.add(p, s), owner.push_back(-1);
  }
  // 4. Convex hull less the faces spanning one loop; where the thinning left a gap (a face
  // whose circumradius exceeds 0.7 x its vertices' spacing), its circumcentre on the sphere
  // is added and the hull taken again (Delaunay refinement, at most 3 rounds).
  TriangleMesh m;
  std::vector<Kernel::Point_3> kp;
  std::vector<std::size_t> index;
  std::vector<std::size_t> hull_vertices;
  std::vector<std::array<int, 3>> faces;
  std::vector<std::array<int, 3>> seeds;  // of the points added by the last round: the face whose gap each fills
  std::size_t added_from = 0;
  for (int round = 0;; ++round) {
    // A loop vertex that a wall ring moved off the sphere (snap_holes_to_rings moves it along
    // z or along a chord) may fall inside the hull of its neighbours: the hull is taken of it
    // moved radially back onto the sphere, the mesh keeps it where its other owners have it.
    kp.clear();
    for (std::size_t v = 0; v < pts.points.size(); ++v) {
      Eigen::Vector3d p = pts.points[v];
      if (owner[v] >= 0 && std::abs((p - c).norm() - r) > 1e-9 * r) p = c + r * (p - c).normalized();
      kp.emplace_back(p.x(), p.y(), p.z());
    }
    // After the first round, the points the refinement added go into the last hull one by one;
    // the hull is taken afresh when that fails. CGAL's hull is over the points' indices (its
    // adapter reads each point through the map), so its vertices come out as indices into
    // pts.points; CGAL 5.5 declares a template parameter of this overload that no argument
    // deduces, hence the explicit `void`.
    // The point inside the hull is its points' mean, not the sphere's centre: a clip plane may
    // keep less than half the sphere, whose centre then lies outside.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t v = 0; v < added_from; ++v) mean += pts.points[v] / static_cast<double>(added_from);
    if (round == 0 || !insert_into_hull(faces, kp, added_from, seeds, Kernel::Point_3(mean.x(), mean.y(), mean.z()))) {
      index.resize(kp.size());
      std::iota(index.begin(), index.end(), std::size_t{0});
      hull_vertices.clear();
      faces.clear();
      CGAL::convex_hull_3<std::vector<std::size_t>::const_iterator, void>(
          index.cbegin(), index.cend(), hull_vertices, faces,
          CGAL::make_extreme_points_traits_adapter(CGAL::make_property_map(kp)));
      for (auto& t : faces)
        for (int& v : t) v = static_cast<int>(hull_vertices[v]);
    }
    canonical_flat_facets(faces, kp);
    m.triangles.clear();
    for (auto t : faces) {
      if (owner[t[0]] >= 0 && owner[t[0]] == owner[t[1]] && owner[t[0]] == owner[t[2]]) {
        const SphereCut& cut = cuts[owner[t[0]]];
        if (!cut.spans || cut.spans(pts.points[t[0]], pts.points[t[1]], pts.points[t[2]])) continue;
      }
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      m.triangles.push_back(t);
    }
    // CGAL lists the hull's faces in an order that changes from call to call; the refinement
    // below depends on the order, so sort them for the same mesh every run.
    std::sort(m.triangles.begin(), m.triangles.end());
    if (round == 3) break;
    const std::size_t before = pts.points.size();
    seeds.clear();
    for (const auto& t : m.triangles) {
      const Eigen::Vector3d &a = pts.points[t[0]], &b = pts.points[t[1]], &q = pts.points[t[2]];
      const Eigen::Vector3d ab = b - a, aq = q - a, n = ab.cross(aq);
      const Eigen::Vector3d centre = a + (aq.squaredNorm() * n.cross(ab) + ab.squaredNorm() * aq.cross(n)) / (2.0 * n.squaredNorm());
      const double local = std::max({pts.spacing(t[0]), pts.spacing(t[1]), pts.spacing(t[2])});
      if ((centre - a).norm() <= 0.7 * local) continue;
      const Eigen::Vector3d p = c + r * (centre - c).normalized();
      if (!is_removed(p) && pts.fits(p, 0.7 * local)) pts.add(p, local), owner.push_back(-1), seeds.push_back(t);
    }
    if (pts.points.size() == before) break;
    added_from = before;
  }
  m.points = pts.points;
  std::unordered_set<std::uint64_t> edges;
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) edges.insert(edge_key(t[e], t[(e + 1) % 3]));
  for (int first = 0, k = 0; k < static_cast<int>(cuts.size()); first += static_cast<int>(cuts[k].loop.size()), ++k) {
    const int n = static_cast<int>(cuts[k].loop.size());
    for (int j = 0; j < n; ++j)
      if (!edges.count(edge_key(first + j, first + (j + 1) % n)))
        throw CutConflict("a cut's loop is not an edge path of the sphere mesh (cuts too close together or crossing)");
  }
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient_by(m, [&](const Eigen::Vector3d& q) { return outward ? Eigen::Vector3d(q - c) : Eigen::Vector3d(c - q); });
  return m;
}

double match_sphere_volume(TriangleMesh& m, const Eigen::Vector3d& c, double r, const std::vector<SphereCut>& cuts,
                           const std::function<double(const Eigen::Vector3d&)>& clearance) {
  std::size_t on_loops = 0;  // sphere_mesh's first points
  for (const SphereCut& cut : cuts) on_loops += cut.loop.size();
  // Per vertex: the area of its triangles, and their area times their mean depth inside the sphere.
  std::vector<double> area(m.points.size(), 0.0), deficit(m.points.size(), 0.0);
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d &a = m.points[t[0]], &b = m.points[t[1]], &q = m.points[t[2]];
    const double A = 0.5 * (b - a).cross(q - a).norm();
    const double depth = ((b - a).squaredNorm() + (q - b).squaredNorm() + (a - q).squaredNorm()) / (24.0 * r);
    for (int v : t) area[v] += A, deficit[v] += A * depth;
  }
  double largest = 0.0;
  for (std::size_t v = on_loops; v < m.points.size(); ++v) {
    Eigen::Vector3d& x = m.points[v];
    if (!(area[v] > 0.0)) continue;
    // The move wanted, and the room for it: the distance to the nearest other surface, or along
    // the ray to where the fluid ends (bisection; a plane or a wall is crossed once), looked for
    // out to where it no longer limits the move.
    const double wanted = deficit[v] / area[v];
    const double edge = std::sqrt(8.0 * r * wanted);  // the root mean square of its triangles' edges
    const double reach = edge + 8.0 * wanted;
    double room = clearance ? std::min(reach, clearance(x)) : reach;
    const Eigen::Vector3d out = (x - c).normalized();
    const auto removed = [&](double t) {
      return std::any_of(cuts.begin(), cuts.end(),
                         [&](const SphereCut& cut) { return cut.fluid_ends && cut.removed(x + t * out); });
    };
    if (removed(room)) {
      double lo = 0.0, hi = room;
      for (int k = 0; k < 30; ++k) (removed(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
      room = lo;
    }
    const double push = std::clamp((room - edge) / 8.0, 0.0, wanted);
    if (std::any_of(cuts.begin(), cuts.end(), [&](const SphereCut& cut) { return cut.removed(x + push * out); })) continue;
    x += push * out;
    largest = std::max(largest, push);
  }
  return largest;
}

double chordal_deviation(const TriangleMesh& m, const Eigen::Vector3d& c, double r) {
  double worst = 0.0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d n = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]).normalized();
    worst = std::max(worst, r - std::abs(n.dot(m.points[t[0]] - c)));
  }
  return worst;
}

namespace {

// Rings along a tube: about one per sqrt(3)/2 of the loop spacing over the longest generator,
// at least one; the end loop is staggered when their number is odd.
int tube_rings(double rho, int n, const GeneratorLength& length, double edge) {
  const double step = std::min(edge, 2.0 * std::numbers::pi * rho / n);
  double longest = 0.0;
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d q = on_circle(rho, j, n, false, 0.0);
    longest = std::max(longest, length(q.x(), q.y()));
  }
  return std::max(1, static_cast<int>(std::lround(longest / (std::sqrt(3.0) / 2.0 * step))));
}

}  // namespace

std::vector<Eigen::Vector3d> tube_end_loop(const Frame& f, double rho, int n, const GeneratorLength& length, double edge) {
  const bool stagger = tube_rings(rho, n, length, edge) % 2 == 1;
  std::vector<Eigen::Vector3d> loop;
  for (int j = 0; j < n; ++j) {
    Eigen::Vector3d local = on_circle(rho, j, n, stagger, 0.0);
    local.z() = length(local.x(), local.y());
    loop.push_back(f.to_world(local));
  }
  return loop;
}

TriangleMesh tube_mesh(const Frame& f, double rho, int n, const GeneratorLength& length, double edge, bool outward,
                       const std::string& patch) {
  TriangleMesh m;
  const int nz = tube_rings(rho, n, length, edge);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j < n; ++j) {
      Eigen::Vector3d local = on_circle(rho, j, n, k % 2 == 1, 0.0);
      if (k == nz) local.z() = length(local.x(), local.y());
      else if (k > 0) local.z() = length(local.x(), local.y()) * k / nz;
      m.points.push_back(f.to_world(local));
    }
  auto at = [&](int k, int j) { return k * n + (j % n); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j) {
      if (k % 2 == 0) {  // ring k+1 is half a step ahead
        m.triangles.push_back({at(k, j), at(k, j + 1), at(k + 1, j)});
        m.triangles.push_back({at(k + 1, j), at(k, j + 1), at(k + 1, j + 1)});
      } else {  // ring k is half a step ahead
        m.triangles.push_back({at(k, j), at(k + 1, j + 1), at(k + 1, j)});
        m.triangles.push_back({at(k, j), at(k, j + 1), at(k + 1, j + 1)});
      }
    }
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient_by(m, [&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d d = q - f.origin, radial = d - d.dot(f.w) * f.w;
    return outward ? radial : Eigen::Vector3d(-radial);
  });
  return m;
}

TriangleMesh ring_mesh(const Frame& f, double r_in, double r_out, double edge, double jitter, bool along_w,
                       const std::string& patch) {
  TriangleMesh m;
  const int rings = std::max(1, static_cast<int>(std::ceil((r_out - r_in) / (edge * std::sqrt(3.0) / 2.0))));
  // Ring k from the inside out; ring 0 of a disk is its centre. The sites between the edge loops
  // move by up to jitter / 2 of the edge (see the header).
  Rng nudge(1);
  std::vector<Eigen::Vector2d> sites;
  std::vector<std::vector<int>> loops;  // the edge loops, kept as constraints
  for (int k = 0; k <= rings; ++k) {
    const double rho = k == rings ? r_out : r_in + (r_out - r_in) * k / rings;
    const bool loop = k == rings || (k == 0 && rho > 0.0);
    const int n = rho <= 0.0 ? 1 : loop ? ring_points(rho, edge) : std::max(6, ring_points(rho, edge));
    if (loop) loops.emplace_back();
    for (const Eigen::Vector3d& p : rho <= 0.0 ? std::vector<Eigen::Vector3d>{f.origin} : circle_loop(f, rho, n)) {
      Eigen::Vector2d q((p - f.origin).dot(f.u), (p - f.origin).dot(f.v));
      if (loop) {
        loops.back().push_back(static_cast<int>(sites.size()));
        m.points.push_back(p);  // as the walls' end rows have them, bit for bit
      } else {
        q += jitter * edge * Eigen::Vector2d(nudge.uniform() - 0.5, nudge.uniform() - 0.5);
        m.points.push_back(f.to_world(Eigen::Vector3d(q.x(), q.y(), 0.0)));
      }
      sites.push_back(q);
    }
  }
  Cdt cdt;
  const std::vector<Cdt::Vertex_handle> handle = insert_in_rows(cdt, sites, edge);
  for (const auto& loop : loops)
    for (std::size_t k = 0; k < loop.size(); ++k) cdt.insert_constraint(handle[loop[k]], handle[loop[(k + 1) % loop.size()]]);
  for (auto fh : cdt.finite_face_handles()) {
    const std::array<int, 3> t{fh->vertex(0)->info(), fh->vertex(1)->info(), fh->vertex(2)->info()};
    if ((sites[t[0]] + sites[t[1]] + sites[t[2]]).norm() / 3.0 > r_in) m.triangles.push_back(t);  // not in the hole
  }
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient_by(m, [&](const Eigen::Vector3d&) { return along_w ? f.w : Eigen::Vector3d(-f.w); });
  return m;
}

}  // namespace bedforge::meshing
