#include "meshing/surface/delaunay_walls.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "core/edge_key.hpp"
#include "meshing/surface/delaunay_facets.hpp"
#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

namespace {

// Whether some sphere through the corners of triangle t holds none of the points within
// `reach` of it: then t is a facet of their Delaunay tetrahedra. The spheres through the corners
// have their centres on the normal through the circumcentre C, at C + s n; a point P lies
// outside the one at s when 2 s h <= |P - C|^2 - c^2 (h = (P - C) . n, c the circumradius), a
// bound on s from above or below. Points beyond `reach` (all of them, unseen) leave every s with
// |s| < (reach^2 - c^2) / (2 reach) free, so the interval is cut to that: a triangle this passes
// is a facet whatever lies beyond; one it fails may be too (then it is split needlessly), and
// near-ties fail.
bool has_empty_circumsphere(const TriangleMesh& f, const std::array<int, 3>& t, const PointsByCell& grid, double reach) {
  const Eigen::Vector3d &p0 = f.points[t[0]], &p1 = f.points[t[1]], &p2 = f.points[t[2]];
  const Eigen::Vector3d a = p0 - p2, b = p1 - p2, axb = a.cross(b);
  const double area2 = axb.squaredNorm();
  if (area2 == 0.0) return false;
  const Eigen::Vector3d centre = p2 + (a.squaredNorm() * b - b.squaredNorm() * a).cross(axb) / (2.0 * area2);
  const Eigen::Vector3d n = axb / std::sqrt(area2);
  const double c2 = (p0 - centre).squaredNorm();
  if (c2 >= reach * reach) return false;
  const double free = (reach * reach - c2) / (2.0 * reach);
  double lo = -free, hi = free;
  bool inside = false;
  grid.near(centre, [&](int v) {
    if (v == t[0] || v == t[1] || v == t[2]) return;
    const Eigen::Vector3d q = f.points[v] - centre;
    const double d2 = q.squaredNorm();
    if (d2 >= reach * reach) return;
    const double h = q.dot(n), bound = (d2 - c2) / (2.0 * h);
    if (h > 0.0) hi = std::min(hi, bound);
    else if (h < 0.0) lo = std::max(lo, bound);
    else inside |= d2 < c2;
  });
  return !inside && lo < hi - 1e-9 * reach;
}

// Of the triangles `candidates` of f (which failed has_empty_circumsphere), those that are
// not facets of the Delaunay tetrahedra of the points within `reach` of one of them.
std::vector<std::size_t> certainly_missing(const TriangleMesh& f, const std::vector<std::size_t>& candidates,
                                           const PointsByCell& grid, double reach) {
  std::vector<int> near;
  std::unordered_set<int> seen;
  for (std::size_t t : candidates) {
    const Eigen::Vector3d centroid = (f.points[f.triangles[t][0]] + f.points[f.triangles[t][1]] + f.points[f.triangles[t][2]]) / 3.0;
    grid.near(centroid, [&](int v) {
      if ((f.points[v] - centroid).squaredNorm() < reach * reach && seen.insert(v).second) near.push_back(v);
    });
  }
  return off_delaunay_facets(f, near, candidates);
}

// The corner of triangle t that is neither a nor b.
int opposite(const std::array<int, 3>& t, int a, int b) {
  for (int v : t)
    if (v != a && v != b) return v;
  return -1;
}

// The midpoint of edge (a, b) of a wall, moved out onto the cylinder.
Eigen::Vector3d midpoint_on_wall(const SurfacePiece& wall, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d q = 0.5 * (a + b) - wall.centre;
  const Eigen::Vector3d along = q.dot(wall.axis) * wall.axis, radial = q - along;
  return wall.centre + along + radial * (wall.radius / radial.norm());
}

// A split must not leave slivers: each of the four new triangles keeps at least this angle.
// Triangles along a hole's loop, whose loop edge cannot be split, would otherwise thin round by
// round (0.47 degrees on the a = 5, N = 1e4 enlarge surface); such a triangle is left to gmsh.
constexpr double kSmallestNewAngleDeg = 10.0;

}  // namespace

WallDelaunaySplits split_wall_triangles_off_delaunay(TriangleMesh& f, std::vector<SurfacePiece>& pieces, double band,
                                                     const std::vector<double>& rings, int max_rounds) {
  WallDelaunaySplits out;
  std::vector<std::size_t> walls;
  for (std::size_t k = 0; k < pieces.size(); ++k)
    if (pieces[k].shape == SurfacePiece::Shape::cylinder) walls.push_back(k);
  if (walls.empty()) return out;

  // 1. The points within `band` of a wall, by cell.
  PointsByCell grid(band);
  for (std::size_t v = 0; v < f.points.size(); ++v)
    for (std::size_t w : walls)
      if (std::abs(from_axis(f.points[v], pieces[w].centre, pieces[w].axis) - pieces[w].radius) < band) {
        grid.add(f.points[v], static_cast<int>(v));
        break;
      }

  // The surface as it was, to go back to when the splits cannot finish.
  std::vector<std::array<int, 3>> triangles_before;
  std::vector<int> patch_before;
  std::vector<SurfacePiece> pieces_before;
  const std::size_t points_before = f.points.size();
  for (;; ++out.rounds) {
    // 2. The wall triangles with no empty circumsphere, and the longest of each one's edges
    // shared with another wall triangle (a hole's loop or the strip's end row is left as it is).
    std::vector<std::size_t> wall_triangles;
    for (std::size_t w : walls)
      for (std::size_t t = pieces[w].first; t < pieces[w].last; ++t) wall_triangles.push_back(t);
    std::vector<char> failed(wall_triangles.size());
#pragma omp parallel for schedule(dynamic, 4096)
    for (std::size_t k = 0; k < wall_triangles.size(); ++k)
      failed[k] = !has_empty_circumsphere(f, f.triangles[wall_triangles[k]], grid, band);
    std::vector<std::size_t> candidates;
    for (std::size_t k = 0; k < wall_triangles.size(); ++k)
      if (failed[k]) candidates.push_back(wall_triangles[k]);
    const std::vector<std::size_t> missing =
        candidates.empty() ? candidates : certainly_missing(f, candidates, grid, 0.5 * band);
    const std::size_t n_missing = missing.size();
    if (out.rounds == 0) out.missing_before = n_missing;
    out.missing_after = n_missing;
    if (n_missing == 0 || out.rounds == max_rounds) break;
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> edge_triangles;
    for (std::size_t t : wall_triangles)
      for (int k = 0; k < 3; ++k) edge_triangles[edge_key(f.triangles[t][k], f.triangles[t][(k + 1) % 3])].push_back(t);
    auto wall_of = [&](std::size_t t) {
      for (std::size_t w : walls)
        if (t >= pieces[w].first && t < pieces[w].last) return w;
      return walls[0];
    };
    // A split: edge (a, b) and its new vertex, chosen by the angle guard.
    struct Split {
      int a, b;
      Eigen::Vector3d point;
    };
    std::vector<Split> split;
    std::unordered_set<std::size_t> touched;
    for (std::size_t t : missing) {
      if (touched.count(t)) continue;
      const auto& tri = f.triangles[t];
      std::array<int, 3> order{0, 1, 2};
      auto length = [&](int e) { return (f.points[tri[e]] - f.points[tri[(e + 1) % 3]]).squaredNorm(); };
      std::sort(order.begin(), order.end(), [&](int a, int b) { return length(a) > length(b); });
      for (int e : order) {
        const int a = tri[e], b = tri[(e + 1) % 3];
        const auto& shared = edge_triangles.at(edge_key(a, b));
        const bool on_ring = f.points[a].z() == f.points[b].z() &&
                             std::find(rings.begin(), rings.end(), f.points[a].z()) != rings.end();
        if (on_ring || shared.size() != 2 || touched.count(shared[0]) || touched.count(shared[1])) continue;
        const Eigen::Vector3d m = midpoint_on_wall(pieces[wall_of(t)], f.points[a], f.points[b]);
        double smallest = 180.0;
        for (std::size_t s : shared) {
          const Eigen::Vector3d& c = f.points[opposite(f.triangles[s], a, b)];
          smallest = std::min({smallest, min_angle_deg(f.points[a], m, c), min_angle_deg(m, f.points[b], c)});
        }
        if (smallest < kSmallestNewAngleDeg) continue;
        touched.insert(shared.begin(), shared.end());
        split.push_back({a, b, m});
        break;
      }
    }
    if (split.empty()) break;
    if (out.edges_split == 0) triangles_before = f.triangles, patch_before = f.patch, pieces_before = pieces;
    // 3. Each edge split at its midpoint on the wall; each of its two triangles becomes two, the
    // second appended to its wall's range.
    std::vector<std::vector<std::array<int, 3>>> added(pieces.size());
    for (const Split& e : split) {
      const int a = e.a, b = e.b, m = static_cast<int>(f.points.size());
      f.points.push_back(e.point);
      grid.add(e.point, m);
      for (std::size_t t : edge_triangles.at(edge_key(a, b))) {
        std::array<int, 3> first = f.triangles[t], second = f.triangles[t];
        for (int k = 0; k < 3; ++k) {
          if (first[k] == b) first[k] = m;
          if (second[k] == a) second[k] = m;
        }
        f.triangles[t] = first;
        added[wall_of(t)].push_back(second);
      }
      ++out.edges_split;
    }
    // The ranges stay contiguous: every piece's new triangles go right after its own.
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> patch;
    triangles.reserve(f.triangles.size() + 2 * split.size());
    patch.reserve(triangles.capacity());
    std::size_t next = 0;
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      SurfacePiece& p = pieces[k];
      for (std::size_t t = next; t < p.last; ++t) triangles.push_back(f.triangles[t]), patch.push_back(f.patch[t]);
      const int wall_patch = p.last > p.first ? f.patch[p.first] : 0;
      for (const auto& t : added[k]) triangles.push_back(t), patch.push_back(wall_patch);
      next = p.last;
      p.first = k == 0 ? 0 : pieces[k - 1].last;
      p.last = triangles.size();
    }
    for (std::size_t t = next; t < f.triangles.size(); ++t) triangles.push_back(f.triangles[t]), patch.push_back(f.patch[t]);
    f.triangles = std::move(triangles);
    f.patch = std::move(patch);
  }
  if (out.missing_after > 0 && out.edges_split > 0) {
    f.points.resize(points_before);
    f.triangles = std::move(triangles_before);
    f.patch = std::move(patch_before);
    pieces = std::move(pieces_before);
    out.kept = false;
  }
  return out;
}

}  // namespace bedforge::meshing
