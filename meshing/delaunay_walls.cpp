#include "meshing/delaunay_walls.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace bedforge::meshing {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

K::Point_3 to_cgal(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
}

double distance_from_axis(const SurfacePiece& w, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = p - w.centre;
  return (q - q.dot(w.axis) * w.axis).norm();
}

}  // namespace

WallDelaunaySplits split_wall_triangles_off_delaunay(TriangleMesh& f, std::vector<SurfacePiece>& pieces, double band,
                                                     int max_rounds) {
  WallDelaunaySplits out;
  std::vector<std::size_t> walls;
  for (std::size_t k = 0; k < pieces.size(); ++k)
    if (pieces[k].shape == SurfacePiece::Shape::cylinder) walls.push_back(k);
  if (walls.empty()) return out;

  // 1. The Delaunay tetrahedra of the points near a wall.
  Delaunay dt;
  std::vector<Delaunay::Vertex_handle> handle(f.points.size());
  {
    std::vector<std::pair<K::Point_3, int>> near;
    for (std::size_t v = 0; v < f.points.size(); ++v)
      for (std::size_t w : walls)
        if (std::abs(distance_from_axis(pieces[w], f.points[v]) - pieces[w].radius) < band) {
          near.emplace_back(to_cgal(f.points[v]), static_cast<int>(v));
          break;
        }
    dt.insert(near.begin(), near.end());
    for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) handle[v->info()] = v;
  }
  auto missing = [&](const std::array<int, 3>& t) {
    Delaunay::Cell_handle c;
    int i, j, k;
    return !dt.is_facet(handle[t[0]], handle[t[1]], handle[t[2]], c, i, j, k);
  };

  for (;; ++out.rounds) {
    // 2. The missing wall triangles, and the longest of each one's edges shared with another
    // wall triangle (a hole's loop or the strip's end row is left as it is).
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> edge_triangles;
    for (std::size_t w : walls)
      for (std::size_t t = pieces[w].first; t < pieces[w].last; ++t)
        for (int k = 0; k < 3; ++k) edge_triangles[edge_key(f.triangles[t][k], f.triangles[t][(k + 1) % 3])].push_back(t);
    std::vector<std::pair<int, int>> split;
    std::unordered_set<std::size_t> touched;
    std::size_t n_missing = 0;
    for (std::size_t w : walls)
      for (std::size_t t = pieces[w].first; t < pieces[w].last; ++t) {
        if (!missing(f.triangles[t])) continue;
        ++n_missing;
        if (touched.count(t)) continue;
        std::array<int, 3> order{0, 1, 2};
        const auto& tri = f.triangles[t];
        auto length = [&](int k) { return (f.points[tri[k]] - f.points[tri[(k + 1) % 3]]).squaredNorm(); };
        std::sort(order.begin(), order.end(), [&](int a, int b) { return length(a) > length(b); });
        for (int k : order) {
          const auto& shared = edge_triangles.at(edge_key(tri[k], tri[(k + 1) % 3]));
          if (shared.size() != 2 || touched.count(shared[0]) || touched.count(shared[1])) continue;
          touched.insert(shared.begin(), shared.end());
          split.emplace_back(tri[k], tri[(k + 1) % 3]);
          break;
        }
      }
    if (out.rounds == 0) out.missing_before = n_missing;
    out.missing_after = n_missing;
    if (n_missing == 0 || split.empty() || out.rounds == max_rounds) break;

    // 3. Each edge split at its midpoint on the wall; each of its two triangles becomes two, the
    // second appended to its wall's range.
    std::vector<std::vector<std::array<int, 3>>> added(pieces.size());
    auto wall_of = [&](std::size_t t) {
      for (std::size_t w : walls)
        if (t >= pieces[w].first && t < pieces[w].last) return w;
      return walls[0];
    };
    for (const auto& [a, b] : split) {
      const std::size_t w = wall_of(edge_triangles.at(edge_key(a, b))[0]);
      const SurfacePiece& wall = pieces[w];
      const Eigen::Vector3d mid = 0.5 * (f.points[a] + f.points[b]), q = mid - wall.centre;
      const Eigen::Vector3d along = q.dot(wall.axis) * wall.axis, radial = q - along;
      const Eigen::Vector3d on_wall = wall.centre + along + radial * (wall.radius / radial.norm());
      const int m = static_cast<int>(f.points.size());
      f.points.push_back(on_wall);
      handle.push_back(dt.insert(to_cgal(on_wall)));
      handle.back()->info() = m;
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
  return out;
}

}  // namespace bedforge::meshing
