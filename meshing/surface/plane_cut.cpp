#include "meshing/surface/plane_cut.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "core/edge_key.hpp"
#include "meshing/surface/delaunay_facets.hpp"
#include "meshing/surface/gap_spacing.hpp"
#include "meshing/surface/planar_cdt.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/spaced_points.hpp"
#include "meshing/surface/wall_mesh.hpp"

namespace bedforge::meshing {

namespace {

Eigen::Vector3d normal(const std::vector<Eigen::Vector3d>& x, const std::array<int, 3>& t) {
  return (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
}

std::string where(const Eigen::Vector3d& q) { return fmt::format("({:.4g}, {:.4g}, {:.4g}) m", q.x(), q.y(), q.z()); }

// The triangles of `part` with a vertex within `band` of the plane z that are no facet of the
// Delaunay tetrahedra of its points within 2 band of the plane and those triangles' corners
// (a long triangle's reach further): more points only take facets away, so each is missing from
// gmsh's start too.
std::vector<std::size_t> off_delaunay_near_plane(const TriangleMesh& part, double z, double band) {
  std::vector<char> taken(part.points.size(), 0);
  for (std::size_t v = 0; v < part.points.size(); ++v) taken[v] = std::abs(part.points[v].z() - z) < 2.0 * band;
  std::vector<std::size_t> beside;
  for (std::size_t t = 0; t < part.triangles.size(); ++t) {
    const auto& v = part.triangles[t];
    if (std::min({std::abs(part.points[v[0]].z() - z), std::abs(part.points[v[1]].z() - z),
                  std::abs(part.points[v[2]].z() - z)}) < band) {
      beside.push_back(t);
      for (int c : v) taken[c] = 1;
    }
  }
  std::vector<int> near;
  for (std::size_t v = 0; v < part.points.size(); ++v)
    if (taken[v]) near.push_back(static_cast<int>(v));
  return off_delaunay_facets(part, near, beside);
}

// What the flips leave for gmsh to recover (where the plane meets a bridge's rim, or a sphere's
// triangle on a loop faces a point of the face), split away: the longest edge of each such
// triangle that does not lie in the plane, at its midpoint, then the flips again, round by round
// (without the flips between, the splits near bridges' rims made more than they took away:
// 22 became 44 on a piece of a = 14, N = 1e4; with them one round took all). A split that would
// make an angle under kSmallestSplitAngleDeg is not made. When some are left after the rounds,
// every split is undone: gmsh's recovery of a few costs it as much as of hundreds, and a split
// dents the surface by its edge's sagitta. The face and the loops are untouched. Returns {edges
// split, triangles left}.
constexpr double kSmallestSplitAngleDeg = 10.0;
std::pair<long, long> split_off_delaunay_near_plane(TriangleMesh& part, double z, double band) {
  long split = 0;
  std::vector<std::size_t> missing = off_delaunay_near_plane(part, z, band);
  if (missing.empty()) return {0, 0};
  const long before = static_cast<long>(missing.size());
  const TriangleMesh unsplit = part;
  for (int round = 0; round < 8 && !missing.empty(); ++round) {
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> edge_triangles;
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) edge_triangles[edge_key(part.triangles[t][k], part.triangles[t][(k + 1) % 3])].push_back(t);
    std::vector<char> touched(part.triangles.size(), 0);
    long this_round = 0;
    for (std::size_t t : missing) {
      if (touched[t]) continue;
      const std::array<int, 3> tri = part.triangles[t];
      std::array<int, 3> order{0, 1, 2};
      auto length = [&](int e) { return (part.points[tri[e]] - part.points[tri[(e + 1) % 3]]).squaredNorm(); };
      std::sort(order.begin(), order.end(), [&](int a, int b) { return length(a) > length(b); });
      for (int e : order) {
        const int a = tri[e], b = tri[(e + 1) % 3];
        if (part.points[a].z() == z && part.points[b].z() == z) continue;
        const std::vector<std::size_t>& shared = edge_triangles.at(edge_key(a, b));
        if (shared.size() != 2 || touched[shared[0]] || touched[shared[1]]) continue;
        const Eigen::Vector3d m = 0.5 * (part.points[a] + part.points[b]);
        double smallest = 180.0;
        for (std::size_t u : shared) {
          const auto& w = part.triangles[u];
          const Eigen::Vector3d& c = part.points[w[0] + w[1] + w[2] - a - b];
          smallest = std::min({smallest, min_angle_deg(part.points[a], m, c), min_angle_deg(m, part.points[b], c)});
        }
        if (smallest < kSmallestSplitAngleDeg) continue;
        const int mid = static_cast<int>(part.points.size());
        part.points.push_back(m);
        for (std::size_t u : shared) {
          std::array<int, 3> first = part.triangles[u], second = first;
          for (int k = 0; k < 3; ++k) {
            if (first[k] == b) first[k] = mid;
            if (second[k] == a) second[k] = mid;
          }
          part.triangles[u] = first;
          part.triangles.push_back(second);
          part.patch.push_back(part.patch[u]);
          touched[u] = 1;
        }
        ++this_round;
        break;
      }
    }
    split += this_round;
    if (this_round == 0) break;
    std::vector<double> height(part.points.size());
    for (std::size_t v = 0; v < part.points.size(); ++v) height[v] = part.points[v].z() - z;
    flip_towards_delaunay(part.points, height, part.triangles, part.patch, band);
    missing = off_delaunay_near_plane(part, z, band);
  }
  if (missing.empty()) return {split, 0};
  part = unsplit;
  return {0, before};
}

}  // namespace

long flip_towards_delaunay(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& s,
                           std::vector<std::array<int, 3>>& tris, const std::vector<int>& patch, double band) {
  auto angle_at = [&](int c, int a, int b) {
    const Eigen::Vector3d u = (x[a] - x[c]).normalized(), v = (x[b] - x[c]).normalized();
    return std::acos(std::clamp(u.dot(v), -1.0, 1.0));
  };
  long flips = 0;
  for (int round = 0; round < 20; ++round) {
    std::unordered_map<std::uint64_t, std::vector<int>> edges;
    for (std::size_t t = 0; t < tris.size(); ++t) {
      const auto& v = tris[t];
      if (std::min({std::abs(s[v[0]]), std::abs(s[v[1]]), std::abs(s[v[2]])}) >= band) continue;
      for (int k = 0; k < 3; ++k) edges[edge_key(v[k], v[(k + 1) % 3])].push_back(static_cast<int>(t));
    }
    std::vector<char> changed(tris.size(), 0);
    long this_round = 0;
    for (const auto& [key, ts] : edges) {
      if (ts.size() != 2 || patch[ts[0]] != patch[ts[1]] || changed[ts[0]] || changed[ts[1]]) continue;
      std::array<int, 3>& t1 = tris[ts[0]];
      std::array<int, 3>& t2 = tris[ts[1]];
      // t1 = (a, b, c) from its edge a -> b shared with t2 = (b, a, d).
      int k = 0;
      while (edge_key(t1[k], t1[(k + 1) % 3]) != key) ++k;
      const int a = t1[k], b = t1[(k + 1) % 3], c = t1[(k + 2) % 3];
      const int d = t2[0] + t2[1] + t2[2] - a - b;
      if (angle_at(c, a, b) + angle_at(d, a, b) <= std::numbers::pi) continue;
      // An edge where the surface folds (a bridge's rim on its sphere) stays: across it the new
      // triangles would span both faces.
      const Eigen::Vector3d m1 = normal(x, t1).normalized(), m2 = normal(x, t2).normalized();
      if (m1.dot(m2) < kFlipCreaseCos) continue;
      if ((s[c] == 0.0 && s[d] == 0.0) || edges.count(edge_key(c, d))) continue;
      const std::array<int, 3> n1{a, d, c}, n2{d, b, c};
      const Eigen::Vector3d pair = (m1 + m2).normalized();
      if (normal(x, n1).normalized().dot(pair) < 0.8 || normal(x, n2).normalized().dot(pair) < 0.8) continue;
      t1 = n1, t2 = n2;
      changed[ts[0]] = changed[ts[1]] = 1;
      ++this_round;
    }
    flips += this_round;
    if (this_round == 0) break;
  }
  return flips;
}

void finish_cut_surface(FluidSurface& out, double d) {
  const TriangleMesh& f = out.fluid;
  out.bed = TriangleMesh();
  for (std::size_t t = 0; t < f.triangles.size(); ++t)
    if (f.patches[f.patch[t]] == "particles") {
      std::array<int, 3> tri = f.triangles[t];
      std::swap(tri[1], tri[2]);
      const int first = static_cast<int>(out.bed.points.size());
      for (int k = 0; k < 3; ++k) out.bed.points.push_back(f.points[tri[k]]);
      out.bed.triangles.push_back({first, first + 1, first + 2});
      out.bed.patch.push_back(out.bed.patch_index("particles"));
    }
  out.bed.weld();
  SurfacePiece all;
  all.first = 0, all.last = f.triangles.size();
  out.pieces = {all};
  const MeshQuality quality = mesh_quality(f);
  out.report["triangles"] = f.triangles.size();
  out.report["min_angle_deg"] = quality.min_angle_deg;
  out.report["min_edge_d"] = quality.min_edge / d;
  out.report["max_edge_d"] = quality.max_edge / d;
}

nlohmann::json to_json(const PlaneCut& c) {
  return {{"loops", c.loops},
          {"vertices_snapped", c.vertices_snapped},
          {"vertices_cleared", c.vertices_cleared},
          {"plane_triangles", c.plane_triangles},
          {"edges_flipped", c.edges_flipped},
          {"edges_split", c.edges_split},
          {"left_to_recover", c.left_to_recover},
          {"ends_graded", c.ends_graded}};
}

PlaneCutParams plane_cut_params(const SurfaceParams& s, double d) {
  return {.edge = s.edge_length_d * d, .growth = s.growth, .cells_per_gap = s.cells_per_gap,
          .finest = std::min(s.contact_edge_length_d, s.edge_length_d) * d};
}

PlaneCutParams plane_cut_params(const SurfaceParams& s, const Bed& bed, const FluidSurface& cut) {
  PlaneCutParams out = plane_cut_params(s, reference_diameter(bed));
  out.ends = cut.ends_near_planes;
  out.spheres = cut.spheres_near_planes;
  out.container = bed.container;
  return out;
}

PlaneCut cut_by_plane(const TriangleMesh& m, double z, const PlaneCutParams& p) {
  PlaneCut out;
  std::vector<Eigen::Vector3d> x = m.points;
  const int nv = static_cast<int>(x.size());
  std::vector<double> s(nv);
  for (int v = 0; v < nv; ++v) s[v] = x[v].z() - z;
  std::vector<std::vector<int>> incident(nv);
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int v : m.triangles[t]) incident[v].push_back(static_cast<int>(t));

  // Where the edge (a, b) crosses the plane, computed from its end below (so the same doubles
  // whichever way round or however numbered it comes).
  auto from_below = [&](int a, int b) { return s[a] < s[b] ? std::pair{a, b} : std::pair{b, a}; };
  auto crossing = [&](int a, int b) {
    std::tie(a, b) = from_below(a, b);
    Eigen::Vector3d q = x[a] + s[a] / (s[a] - s[b]) * (x[b] - x[a]);
    q.z() = z;
    return q;
  };

  // Whether moving vertex v to `to` would turn one of its triangles by more than about 75 degrees.
  auto turns_a_triangle = [&](int v, const Eigen::Vector3d& to) {
    const Eigen::Vector3d from = x[v];
    bool turns = false;
    for (int t : incident[v]) {
      const Eigen::Vector3d before = normal(x, m.triangles[t]);
      x[v] = to;
      const Eigen::Vector3d after = normal(x, m.triangles[t]);
      x[v] = from;
      turns |= !(after.dot(before) > 0.25 * after.norm() * before.norm());
    }
    return turns;
  };

  // 1. Vertices near the plane along a crossing edge move onto it there, nearest first.
  struct Snap {
    double distance;
    int v, other;
    Eigen::Vector3d to;
  };
  std::vector<Snap> snaps;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto [a, b] = from_below(t[k], t[(k + 1) % 3]);
      if (!(s[a] * s[b] < 0.0)) continue;
      const Eigen::Vector3d at = crossing(a, b);
      const double f = s[a] / (s[a] - s[b]), length = (x[b] - x[a]).norm();
      if (f < kPlaneCutSnap) snaps.push_back({f * length, a, b, at});
      if (f > 1.0 - kPlaneCutSnap) snaps.push_back({(1.0 - f) * length, b, a, at});
    }
  std::sort(snaps.begin(), snaps.end(), [&x](const Snap& a, const Snap& b) {
    auto key = [&x](const Snap& q) {
      return std::tuple{q.distance, x[q.v].x(), x[q.v].y(), x[q.v].z(), x[q.other].x(), x[q.other].y()};
    };
    return key(a) < key(b);
  });
  // A vertex where patches meet (a bridge's end on the wall) stays: its link holds the other
  // patch's triangles, which two windows of one bed need not mesh alike, and it would move the
  // patches' common edge.
  std::vector<char> moved(nv, 0), between_patches(nv, 0);
  {
    std::vector<int> patch_of(nv, -1);
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int v : m.triangles[t]) {
        if (patch_of[v] >= 0 && patch_of[v] != m.patch[t]) between_patches[v] = 1;
        patch_of[v] = m.patch[t];
      }
  }
  for (const Snap& snap : snaps) {
    if (s[snap.v] == 0.0 || moved[snap.other] || between_patches[snap.v]) continue;
    // Only where the plane would then pass through the vertex once: its neighbours, in order
    // around it, on one arc above and one below (at a saddle, the necks of bridges and unions,
    // two loops would touch there), any neighbour on the plane between the two (below); and no
    // triangle turned by more than about 75 degrees.
    bool ok = !turns_a_triangle(snap.v, snap.to);
    std::unordered_map<int, int> after_in_link;  // neighbour -> the next one around the vertex
    for (int t : incident[snap.v]) {
      const auto& tri = m.triangles[t];
      const int k = static_cast<int>(std::find(tri.begin(), tri.end(), snap.v) - tri.begin());
      after_in_link[tri[(k + 1) % 3]] = tri[(k + 2) % 3];
    }
    std::vector<int> signs;  // around the vertex
    for (int u = after_in_link.begin()->first; ok && signs.size() <= after_in_link.size();) {
      signs.push_back((s[u] > 0.0) - (s[u] < 0.0));
      const auto it = after_in_link.find(u);
      if (it == after_in_link.end()) ok = false;
      else if ((u = it->second) == after_in_link.begin()->first) break;
    }
    if (!ok || signs.size() != after_in_link.size()) continue;
    int changes = 0, last = 0;
    const std::size_t n = signs.size();
    for (std::size_t k = 0; k < 2 * n; ++k) {  // twice round, counting from the first nonzero
      const int g = signs[k % n];
      // A neighbour on the plane: the edge to it must be where the surface crosses, between a
      // triangle below and one above (where both are on one side, the solid would touch the
      // plane's face along it).
      if (g == 0 && signs[(k + 1) % n] * signs[(k + n - 1) % n] >= 0) ok = false;
      if (g != 0 && last != 0 && g != last && k >= n) ++changes;
      if (g != 0) last = g;
    }
    if (!ok || changes != 2) continue;
    x[snap.v] = snap.to, s[snap.v] = 0.0, moved[snap.v] = 1;
    ++out.vertices_snapped;
  }

  // 1b. A vertex the snaps left near the plane beside it (a saddle, where the plane would meet
  // the surface twice, one whose snap would turn a triangle, or a neighbour of a point snapped)
  // moves away from it along z: crossing edges cut within a hair of it leave a triangle of a few
  // thousandths of d beside the plane's face, and the four surface points of a flat tetrahedron
  // that no optimiser can move. It goes to where its crossing edges are cut kPlaneCutClearance
  // of the height difference away, at most (and with none, exactly) a tenth of its shortest
  // edge away, unless that turns a triangle. By height, then coordinates, as the snaps, so that
  // both windows of a plane move the same points.
  {
    std::vector<int> near;
    for (int v = 0; v < nv; ++v) {
      bool beside = false;
      for (int t : incident[v])
        for (int u : m.triangles[t]) beside |= s[u] * s[v] <= 0.0;
      if (s[v] != 0.0 && !between_patches[v] && beside) near.push_back(v);
    }
    std::sort(near.begin(), near.end(), [&](int a, int b) {
      return std::tuple{std::abs(s[a]), x[a].x(), x[a].y(), x[a].z()} <
             std::tuple{std::abs(s[b]), x[b].x(), x[b].y(), x[b].z()};
    });
    for (int v : near) {
      double across = 0.0, shortest = std::numeric_limits<double>::infinity();
      for (int t : incident[v])
        for (int u : m.triangles[t]) {
          if (u == v) continue;
          if (s[u] * s[v] < 0.0) across = std::max(across, std::abs(s[u]));
          shortest = std::min(shortest, (x[u] - x[v]).norm());
        }
      double clear = 0.1 * shortest;
      if (across > 0.0) clear = std::min(clear, kPlaneCutClearance / (1.0 - kPlaneCutClearance) * across);
      if (std::abs(s[v]) >= clear) continue;
      const double to = std::copysign(clear, s[v]);
      if (turns_a_triangle(v, Eigen::Vector3d(x[v].x(), x[v].y(), z + to))) continue;
      x[v].z() = z + to, s[v] = to;
      ++out.vertices_cleared;
    }
  }

  // 2. Each edge still crossing gets one point on the plane, shared by its two triangles.
  std::unordered_map<std::uint64_t, int> cut_point;
  auto cut = [&](int a, int b) {
    const auto [it, added] = cut_point.try_emplace(edge_key(a, b), static_cast<int>(x.size()));
    if (added) x.push_back(crossing(a, b)), s.push_back(0.0);
    return it->second;
  };

  // 3. Triangles to their side, split where they cross (orientation kept).
  std::vector<std::array<int, 3>> below, above;
  std::vector<int> below_patch, above_patch;
  auto keep = [&](const std::array<int, 3>& t, int side, int patch) {
    (side < 0 ? below : above).push_back(t);
    (side < 0 ? below_patch : above_patch).push_back(patch);
  };
  auto sign = [&](int v) { return (s[v] > 0.0) - (s[v] < 0.0); };
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& v = m.triangles[t];
    const int patch = m.patch[t];
    const std::array<int, 3> g{sign(v[0]), sign(v[1]), sign(v[2])};
    const int lo = std::min({g[0], g[1], g[2]}), hi = std::max({g[0], g[1], g[2]});
    if (lo == 0 && hi == 0)
      throw std::runtime_error(fmt::format("plane cut at z = {} m: a surface triangle lies in the plane, at {}", z,
                                           where(x[v[0]])));
    if (hi <= 0 || lo >= 0) {
      keep(v, hi <= 0 ? -1 : 1, patch);
      continue;
    }
    // Rotate so that v[k] is the vertex alone on its side (or on the plane).
    int k = static_cast<int>(std::find(g.begin(), g.end(), 0) - g.begin());
    if (k == 3)
      for (int j = 0; j < 3; ++j)
        if (g[j] != g[(j + 1) % 3] && g[j] != g[(j + 2) % 3]) k = j;
    const int l = v[k], a = v[(k + 1) % 3], b = v[(k + 2) % 3];
    if (g[k] == 0) {  // through a vertex: two triangles
      const int c = cut(a, b);
      keep({l, a, c}, sign(a), patch);
      keep({l, c, b}, sign(b), patch);
      continue;
    }
    const int ca = cut(l, a), cb = cut(l, b);
    keep({l, ca, cb}, g[k], patch);
    // The quad (ca, a, b, cb) by its shorter diagonal.
    if ((x[b] - x[ca]).squaredNorm() <= (x[a] - x[cb]).squaredNorm())
      keep({ca, a, b}, -g[k], patch), keep({ca, b, cb}, -g[k], patch);
    else
      keep({ca, a, cb}, -g[k], patch), keep({a, b, cb}, -g[k], patch);
  }

  if (p.delaunay_flips)
    out.edges_flipped = flip_towards_delaunay(x, s, below, below_patch, 2.0 * p.edge) +
                        flip_towards_delaunay(x, s, above, above_patch, 2.0 * p.edge);

  // 4. The loops on the plane: the edges of the part below that no second triangle below shares,
  // directed as the part below has them; the part above must have the same edges.
  auto open_edges = [](const std::vector<std::array<int, 3>>& tris) {
    std::unordered_map<std::uint64_t, std::pair<int, int>> seen;  // key -> (count, directed edge's start)
    for (const auto& t : tris)
      for (int k = 0; k < 3; ++k) {
        auto& e = seen[edge_key(t[k], t[(k + 1) % 3])];
        ++e.first;
        e.second = t[k];
      }
    std::vector<std::pair<int, int>> open;
    for (const auto& [key, e] : seen)
      if (e.first == 1) {
        const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
        open.push_back(e.second == a ? std::pair{a, b} : std::pair{b, a});
      }
    std::sort(open.begin(), open.end());
    return open;
  };
  const std::vector<std::pair<int, int>> open = open_edges(below);
  {
    std::vector<std::pair<int, int>> reversed;
    for (const auto& [a, b] : open_edges(above)) reversed.push_back({b, a});
    std::sort(reversed.begin(), reversed.end());
    if (reversed != open || open.empty()) {
      std::vector<std::pair<int, int>> odd;
      std::set_symmetric_difference(open.begin(), open.end(), reversed.begin(), reversed.end(), std::back_inserter(odd));
      throw std::runtime_error(fmt::format("plane cut at z = {} m: the surface is not closed along the plane ({} and {} "
                                           "open edges below and above, the first unmatched at {})",
                                           z, open.size(), reversed.size(), odd.empty() ? "none" : where(x[odd[0].first])));
    }
  }
  std::unordered_map<int, int> next;
  for (const auto& [a, b] : open) {
    if (s[a] != 0.0 || s[b] != 0.0)
      throw std::runtime_error(fmt::format("plane cut at z = {} m: the surface is open at {}", z, where(x[a])));
    if (!next.emplace(a, b).second)
      throw CutConflict(fmt::format("the plane at z = {} m meets the surface where two loops touch, at {}", z, where(x[a])));
  }
  std::vector<std::vector<int>> loops;
  std::unordered_map<int, char> done;
  for (const auto& [start, unused] : open) {
    if (done[start]) continue;
    loops.emplace_back();
    for (int v = start; !done[v]; v = next.at(v)) done[v] = 1, loops.back().push_back(v);
  }
  // In an order of their points alone, not of the vertices' numbers: each loop from its least
  // point (x, then y), the loops by that point; so the face is a function of the section.
  auto less = [&](int a, int b) { return std::pair{x[a].x(), x[a].y()} < std::pair{x[b].x(), x[b].y()}; };
  for (auto& loop : loops) std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end(), less), loop.end());
  std::sort(loops.begin(), loops.end(), [&](const auto& a, const auto& b) { return less(a[0], b[0]); });

  // 5. The faces: each loop clockwise from above (the walls, or fluid that solid rings in on the
  // plane) less the anticlockwise loops it is the nearest to hold.
  struct Loop {
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> xy;
    double area = 0.0, spacing = 0.0;
  };
  std::vector<Loop> outer, inner;
  for (const auto& loop : loops) {
    Loop l;
    double perimeter = 0.0;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const Eigen::Vector3d& a = x[loop[k]];
      const Eigen::Vector3d& b = x[loop[(k + 1) % loop.size()]];
      l.area += 0.5 * (a.x() * b.y() - b.x() * a.y());
      perimeter += (b - a).norm();
      l.points.push_back(a), l.xy.emplace_back(a.x(), a.y());
    }
    l.spacing = perimeter / static_cast<double>(loop.size());
    (l.area < 0.0 ? outer : inner).push_back(std::move(l));
  }
  std::vector<std::vector<WallHole>> holes(outer.size());
  for (const Loop& h : inner) {
    int holder = -1;
    for (std::size_t o = 0; o < outer.size(); ++o)
      if (inside_polygon(outer[o].xy, h.xy[0]) && (holder < 0 || outer[o].area > outer[holder].area))
        holder = static_cast<int>(o);
    if (holder < 0)
      throw CutConflict(fmt::format("the plane at z = {} m cuts the solid in a loop outside every face of the fluid, at {}",
                                    z, where(h.points[0])));
    holes[holder].push_back({h.points, h.spacing, -1});
  }
  // The face's spacing across narrow gaps, from its loops (both windows of a plane have the same
  // loops) and the spheres near it (both windows hold them): each loop point with its normal into
  // the fluid, which lies on the right of every loop (outer loops run clockwise, holes
  // anticlockwise), and each sphere by its nearest point.
  const double reach = p.cells_per_gap * p.edge;
  std::vector<Eigen::Vector3d> loop_point, fluid_side, centre;
  std::vector<double> loop_spacing, radius;
  PointsByCell near_loop(reach > 0.0 ? reach : p.edge);
  for (const SphereNearPlane& b : p.spheres)
    if (std::abs(b.centre.z() - z) < b.radius + kSpheresNearPlaneReach * reach) centre.push_back(b.centre), radius.push_back(b.radius);
  if (!centre.empty() && !p.container) throw std::invalid_argument("cut_by_plane: spheres given without their container");
  const std::vector<char> kept(centre.size(), 1);
  std::optional<GapSpacing> surface_spacing;
  if (p.container) surface_spacing.emplace(centre, radius, kept, *p.container, p.cells_per_gap, p.finest, p.edge);
  PointsByCell near_sphere(reach + (radius.empty() ? 0.0 : *std::max_element(radius.begin(), radius.end())));
  // The surface's own spacing at a point of it (GapSpacing, as build_fluid_surface gave the
  // spheres and walls): on the sphere it lies on (within twice the sagitta of an edge), else on
  // a wall; without the spheres, the edge.
  auto spacing_at = [&](const Eigen::Vector3d& q, int sphere) {
    return surface_spacing ? surface_spacing->at(q, sphere) : p.edge;
  };
  SpacingField field;
  if (reach > 0.0) {
    for (std::size_t i = 0; i < centre.size(); ++i) near_sphere.add({centre[i].x(), centre[i].y(), z}, static_cast<int>(i));
    for (const auto& loop : loops)
      for (std::size_t k = 0; k < loop.size(); ++k) {
        const Eigen::Vector3d& q = x[loop[k]];
        const Eigen::Vector3d t = x[loop[(k + 1) % loop.size()]] - x[loop[(k + loop.size() - 1) % loop.size()]];
        int on = -1;
        double off = std::numeric_limits<double>::infinity();
        near_sphere.near(q, [&](int i) {
          const double o = std::abs((q - centre[i]).norm() - radius[i]);
          if (o < off && o < p.edge * p.edge / (4.0 * radius[i])) off = o, on = i;
        });
        near_loop.add(q, static_cast<int>(loop_point.size()));
        loop_point.push_back(q);
        loop_spacing.push_back(spacing_at(q, on));
        fluid_side.push_back(Eigen::Vector3d(t.y(), -t.x(), 0.0).normalized());
      }
    // At a point q of the face, the nearest solid point (d1 away, the surface's spacing there h1)
    // and the nearest ahead of it, within 60 degrees of the direction from the first to q (d2,
    // h2): the face's edge is the gap d1 + d2 over cells_per_gap, or the spacing the volume mesh
    // grades to between the two surfaces, h1 + (h2 - h1) d1 / (d1 + d2), if finer.
    field = {[&](const Eigen::Vector3d& q3) {
               const Eigen::Vector3d q(q3.x(), q3.y(), z);
               double d1 = reach, d2 = reach, h1 = p.edge, h2 = p.edge;
               Eigen::Vector3d away = Eigen::Vector3d::Zero();
               near_loop.near(q, [&](int i) {
                 if (const double r = (loop_point[i] - q).norm(); r < d1) {
                   d1 = r, h1 = loop_spacing[i];
                   away = r > 1e-9 * reach ? Eigen::Vector3d((q - loop_point[i]) / r) : fluid_side[i];
                 }
               });
               near_sphere.near(q, [&](int i) {
                 const Eigen::Vector3d w = q - centre[i];
                 const double n = w.norm();
                 if (const double r = std::max(0.0, n - radius[i]); r < d1 && n > 0.0)
                   d1 = r, away = w / n, h1 = spacing_at(centre[i] + radius[i] * away, static_cast<int>(i));
               });
               if (away.isZero()) return p.edge;
               near_loop.near(q, [&](int i) {
                 const Eigen::Vector3d w = loop_point[i] - q;
                 if (const double r = w.norm(); r < d2 && w.dot(away) > 0.5 * r) d2 = r, h2 = loop_spacing[i];
               });
               near_sphere.near(q, [&](int i) {
                 const Eigen::Vector3d w = centre[i] - q;
                 const double n = w.norm();
                 if (const double r = std::max(0.0, n - radius[i]); r < d2 && w.dot(away) > 0.5 * n)
                   d2 = r, h2 = spacing_at(q + r * w / n, static_cast<int>(i));
               });
               const double graded = d1 + d2 > 0.0 ? h1 + (h2 - h1) * d1 / (d1 + d2) : h1;
               return std::clamp(std::min((d1 + d2) / p.cells_per_gap, graded), p.finest, p.edge);
             },
             p.finest};
  }
  const std::vector<EndNearPlane> ends = ends_at(p.ends, z, p.edge);
  field.seeds = plane_end_seeds(ends, p.edge);
  out.ends_graded = static_cast<long>(ends.size());
  TriangleMesh face;
  for (std::size_t o = 0; o < outer.size(); ++o)
    face.append(plane_mesh(Frame::along({0.0, 0.0, z}, Eigen::Vector3d::UnitZ()), {outer[o].points}, p.edge, holes[o],
                           p.growth, true, p.below_patch, field)
                    .outside);
  out.loops = static_cast<long>(loops.size());
  out.faces = static_cast<long>(outer.size());
  out.plane_triangles = static_cast<long>(face.triangles.size());

  // 6. Each side with the face, which shares the loops' points bit for bit (welded to them).
  auto side = [&](std::vector<std::array<int, 3>>& tris, std::vector<int>& patches, bool up) {
    TriangleMesh part;
    part.points = x;
    part.triangles = std::move(tris);
    part.patch = std::move(patches);
    part.patches = m.patches;
    TriangleMesh f = face;
    if (up) {
      for (auto& t : f.triangles) std::swap(t[1], t[2]);
      f.patches = {p.above_patch};
    }
    part.append(f);
    part.weld();
    drop_unused_points(part);
    return part;
  };
  out.below = side(below, below_patch, false);
  out.above = side(above, above_patch, true);
  if (p.delaunay_flips)
    for (TriangleMesh* part : {&out.below, &out.above}) {
      const auto [split, left] = split_off_delaunay_near_plane(*part, z, 2.0 * p.edge);
      out.edges_split += split, out.left_to_recover += left;
    }
  return out;
}

}  // namespace bedforge::meshing
