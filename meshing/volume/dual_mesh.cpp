#include "meshing/volume/dual_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <tuple>
#include <stdexcept>
#include <unordered_map>

#include "core/edge_key.hpp"
#include "core/point_key.hpp"

namespace bedforge::meshing {

namespace {

// Two boundary faces lie in one plane when their unit normals' dot product exceeds this: a
// plane's triangles (flat at one height, bit for bit) give exactly 1.
constexpr double kFlat = 1.0 - 1e-12;

// Compressed rows: row r holds items[offsets[r]] ... items[offsets[r + 1] - 1].
struct Rows {
  std::vector<int> offsets, items;
  std::span<const int> operator[](int r) const {
    return {items.data() + offsets[r], static_cast<std::size_t>(offsets[r + 1] - offsets[r])};
  }
};

// Rows of `n` from the (row, item) pairs `visit` hands to its callback, the same on both calls
// (one counts, one fills): no per-row vectors, which at millions of rows cost more than the items.
template <class Visit>
Rows make_rows(int n, Visit visit) {
  Rows r;
  r.offsets.assign(n + 1, 0);
  visit([&](int row, int) { ++r.offsets[row + 1]; });
  std::partial_sum(r.offsets.begin(), r.offsets.end(), r.offsets.begin());
  r.items.resize(r.offsets[n]);
  std::vector<int> next(r.offsets.begin(), r.offsets.end() - 1);
  visit([&](int row, int item) { r.items[next[row]++] = item; });
  return r;
}

// Where point p sits in face f (-1 if not on it), and the points before and after it.
int place(const Face& f, int p) {
  for (int k = 0; k < f.size(); ++k)
    if (f[k] == p) return k;
  return -1;
}
int before(const Face& f, int k) { return f[(k + f.size() - 1) % f.size()]; }
int after(const Face& f, int k) { return f[(k + 1) % f.size()]; }

// Whether f, in its stored order, runs from a straight to b.
bool runs(const Face& f, int a, int b) {
  const int k = place(f, a);
  return k >= 0 && after(f, k) == b;
}

std::string where(const Eigen::Vector3d& x) { return fmt::format("({:.6g}, {:.6g}, {:.6g}) m", x.x(), x.y(), x.z()); }

}  // namespace

PolyhedralMesh dual_mesh(const PolyMesh& m, const std::vector<Eigen::Vector3d>& cell_centres, double feature_angle_deg,
                         std::vector<int>* cell_points, bool join_flat) {
  const int n_points = static_cast<int>(m.points.size());
  const int n_cells = m.cells;
  const int n_faces = static_cast<int>(m.faces.size());
  const int n_internal = m.internal_faces();

  std::vector<int> patch_of(n_faces - n_internal, -1);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k)
    for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f) patch_of[f - n_internal] = k;

  // Who touches whom: a cell's faces, a point's cells, a point's boundary faces.
  const Rows cell_faces = make_rows(n_cells, [&](auto add) {
    for (int f = 0; f < n_faces; ++f) {
      add(m.owner[f], f);
      if (f < n_internal) add(m.neighbour[f], f);
    }
  });
  const Rows point_cells = make_rows(n_points, [&](auto add) {
    std::array<int, 8> seen{};
    for (int c = 0; c < n_cells; ++c) {
      int n = 0;
      for (int f : cell_faces[c])
        for (int v : m.faces[f])
          if (std::find(seen.begin(), seen.begin() + n, v) == seen.begin() + n && n < 8) seen[n++] = v;
      for (int k = 0; k < n; ++k) add(seen[k], c);
    }
  });
  const Rows point_boundary = make_rows(n_points, [&](auto add) {
    for (int f = n_internal; f < n_faces; ++f)
      for (int v : m.faces[f]) add(v, f);
  });

  // Dual cells numbered as their points sorted by z.
  std::vector<int> order(n_points), rank(n_points);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.points[a].z() < m.points[b].z(); });
  for (int i = 0; i < n_points; ++i) rank[order[i]] = i;

  std::vector<FaceGeometry> boundary(n_faces - n_internal);
  for (int f = n_internal; f < n_faces; ++f) boundary[f - n_internal] = face_geometry(m.points, m.faces[f]);

  // Feature points, as polyDualMesh marks them: both ends of a boundary edge between patches,
  // sharper than the angle, or not shared by exactly two boundary faces; and points where the
  // boundary faces around do not form one ring (two surfaces touching at a point).
  std::vector<char> feature(n_points, 0);
  const double min_cos = std::cos(feature_angle_deg * std::numbers::pi / 180.0);
  for (int p = 0; p < n_points; ++p) {
    const auto around = point_boundary[p];
    for (int f : around) {
      const int q = after(m.faces[f], place(m.faces[f], p));
      int partner = -1, partners = 0, same_way = 0;
      for (int g : around) {
        if (runs(m.faces[g], q, p)) partner = g, ++partners;
        if (runs(m.faces[g], p, q)) ++same_way;
      }
      const bool sharp = partners == 1 && same_way == 1 &&
                         (patch_of[f - n_internal] != patch_of[partner - n_internal] ||
                          boundary[f - n_internal].area.normalized().dot(boundary[partner - n_internal].area.normalized()) <
                              min_cos);
      if (partners != 1 || same_way != 1 || sharp) feature[p] = feature[q] = 1;
    }
  }
  // The boundary face around p after f, turning about the outward normal: the one whose point
  // after p is the one before p in f (-1 if none).
  auto next_around = [&](int p, int f) {
    const int a = before(m.faces[f], place(m.faces[f], p));
    for (int g : point_boundary[p])
      if (after(m.faces[g], place(m.faces[g], p)) == a) return g;
    return -1;
  };
  for (int p = 0; p < n_points; ++p) {
    const auto around = point_boundary[p];
    if (around.empty() || feature[p]) continue;
    int f = around[0], steps = 0;
    do {
      f = next_around(p, f);
      ++steps;
    } while (f >= 0 && f != around[0] && steps <= static_cast<int>(around.size()));
    if (f != around[0] || steps != static_cast<int>(around.size())) feature[p] = 1;
  }

  // The dual's points: cell centres, boundary face centres, then feature points and edge
  // midpoints as they are first needed.
  PolyhedralMesh d;
  d.points = cell_centres;
  // A boundary triangle's centre from its points in the order of their coordinates, so that a
  // triangle and its copy on a cyclic patch (points the same in x and y, listed the other way
  // round) give the same x and y bit for bit; on a flat face the same z as its points.
  for (int f = n_internal; f < n_faces; ++f) {
    if (m.faces[f].size() != 3) {
      d.points.push_back(boundary[f - n_internal].centre);
      continue;
    }
    std::array<Eigen::Vector3d, 3> t{m.points[m.faces[f][0]], m.points[m.faces[f][1]], m.points[m.faces[f][2]]};
    std::sort(t.begin(), t.end(), coordinates_less);
    d.points.push_back(t[0] + ((t[1] - t[0]) + (t[2] - t[0])) / 3.0);
  }
  const int first_boundary_centre = n_cells - n_internal;  // + boundary face index
  std::vector<int> point_at(n_points, -1);
  for (int p : order)
    if (feature[p]) point_at[p] = static_cast<int>(d.points.size()), d.points.push_back(m.points[p]);
  std::unordered_map<std::uint64_t, int> midpoints;
  auto midpoint = [&](int a, int b) {
    const auto [it, added] = midpoints.emplace(edge_key(a, b), static_cast<int>(d.points.size()));
    if (added) d.points.push_back(0.5 * (m.points[a] + m.points[b]));
    return it->second;
  };

  // The face through which the walk about p -> q (right-handed) leaves cell c: the one that,
  // turned to point out of c, runs from p to q (-1 if c has no such face).
  auto exit_face = [&](int c, int p, int q) {
    for (int f : cell_faces[c])
      if (m.owner[f] == c ? runs(m.faces[f], p, q) : runs(m.faces[f], q, p)) return f;
    return -1;
  };
  auto no_ring = [&](int p, int q) {
    return std::runtime_error(fmt::format("dual mesh: the cells around the edge from {} to {} do not form a ring",
                                          where(m.points[p]), where(m.points[q])));
  };
  // Appends to `polygon` the centres of the cells met walking about p -> q from cell c, until the
  // walk leaves through a boundary face (returned) or comes back to c (-1); no more cells than
  // touch p.
  std::vector<int> polygon;
  auto walk = [&](int c, int p, int q) {
    const int first = c, limit = static_cast<int>(point_cells[p].size());
    for (int steps = 1;; ++steps) {
      polygon.push_back(c);
      const int f = exit_face(c, p, q);
      if (f < 0 || steps > limit) throw no_ring(p, q);
      if (f >= n_internal) return f;
      c = m.owner[f] == c ? m.neighbour[f] : m.owner[f];
      if (c == first) return -1;
    }
  };

  // Internal faces, one per edge (p, q), owned by the lower rank: by owner, then neighbour.
  std::vector<int> ends;
  for (int i = 0; i < n_points; ++i) {
    const int p = order[i];
    ends.clear();
    for (int c : point_cells[p])
      for (int f : cell_faces[c]) {
        const int k = place(m.faces[f], p);
        if (k < 0) continue;
        for (int q : {before(m.faces[f], k), after(m.faces[f], k)})
          if (rank[q] > i) ends.push_back(q);
      }
    std::sort(ends.begin(), ends.end(), [&](int a, int b) { return rank[a] < rank[b]; });
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    for (int q : ends) {
      // On the boundary the walk runs from each boundary face that enters the domain (runs q -> p)
      // to the one that leaves it; inside, once around.
      bool on_boundary = false;
      for (int start : point_boundary[p]) {
        if (!runs(m.faces[start], q, p)) continue;
        on_boundary = true;
        polygon.assign(1, first_boundary_centre + start);
        const int end = walk(m.owner[start], p, q);
        if (end < 0) throw no_ring(p, q);
        polygon.push_back(first_boundary_centre + end);
        if (feature[p] || feature[q]) polygon.push_back(midpoint(p, q));
        d.faces.push_back(polygon);
        d.owner.push_back(i);
        d.neighbour.push_back(rank[q]);
      }
      if (on_boundary) continue;
      int first = -1;
      for (int c : point_cells[p])
        if (exit_face(c, p, q) >= 0) {
          first = c;
          break;
        }
      if (first < 0) throw no_ring(p, q);
      polygon.clear();
      if (walk(first, p, q) >= 0) throw no_ring(p, q);
      d.faces.push_back(polygon);
      d.owner.push_back(i);
      d.neighbour.push_back(rank[q]);
    }
  }

  // Boundary faces, patch by patch: around each boundary point, its faces' centres in turn
  // (with the midpoints of edges to feature points), or at a feature point one quadrilateral
  // per boundary face, the feature point at its corner.
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k) {
    PolyMesh::Patch patch = m.patches[k];
    patch.start = static_cast<int>(d.faces.size());
    for (int i = 0; i < n_points; ++i) {
      const int p = order[i];
      const auto around = point_boundary[p];
      auto on_patch = [&](int f) { return patch_of[f - n_internal] == k; };
      if (std::none_of(around.begin(), around.end(), on_patch)) continue;
      if (feature[p]) {
        // Each run of the patch's faces about p that lie in one plane (an inlet's, an outlet's, a
        // box side's) gives one face: their quadrilaterals joined. On a cyclic pair one small
        // quadrilateral each side, far to the side of both cells' centres, was skewed past
        // checkMesh's limit of 4 where a sphere's cut met the plane (docs/findings.md, 2026-12-01).
        auto in_run = [&](int f, int g) {
          return join_flat && g >= 0 && on_patch(g) &&
                 boundary[f - n_internal].area.normalized().dot(boundary[g - n_internal].area.normalized()) > kFlat;
        };
        std::vector<int> starts;
        for (int f : around) {
          if (!on_patch(f)) continue;
          const bool inside_a_run = std::any_of(around.begin(), around.end(),
                                                [&](int h) { return h != f && next_around(p, h) == f && in_run(h, f); });
          if (!inside_a_run) starts.push_back(f);
        }
        const bool ring = starts.empty();  // a whole flat ring about a feature point: its quadrilaterals
        for (int f : around)
          if (on_patch(f) && (ring || std::count(starts.begin(), starts.end(), f))) {
            polygon.assign({point_at[p], midpoint(p, after(m.faces[f], place(m.faces[f], p)))});
            for (int g = f;;) {
              polygon.push_back(first_boundary_centre + g);
              polygon.push_back(midpoint(before(m.faces[g], place(m.faces[g], p)), p));
              const int next = next_around(p, g);
              if (ring || next == f || !in_run(g, next)) break;
              g = next;
            }
            d.faces.push_back(polygon);
            d.owner.push_back(i);
          }
        continue;
      }
      polygon.clear();
      int f = around[0];
      do {
        polygon.push_back(first_boundary_centre + f);
        const int a = before(m.faces[f], place(m.faces[f], p));
        if (feature[a]) polygon.push_back(midpoint(p, a));
        f = next_around(p, f);
      } while (f != around[0]);
      d.faces.push_back(polygon);
      d.owner.push_back(i);
    }
    patch.size = static_cast<int>(d.faces.size()) - patch.start;
    d.patches.push_back(patch);
  }
  d.cells = n_points;
  if (cell_points) *cell_points = std::move(order);
  return d;
}

namespace {

// The cells of `m` merged by group (new_cell: per cell its group, groups numbered 0.. in the order
// of their first cell): the faces between cells of one group go, the others are kept with their
// cells renumbered, internal ones turned and sorted back into upper-triangular order, points no
// face uses any more dropped.
PolyhedralMesh merged_cells(const PolyhedralMesh& m, const std::vector<int>& new_cell, int cells) {
  PolyhedralMesh out;
  out.cells = cells;
  struct Internal {
    int owner, neighbour, face;
    bool turned;
  };
  std::vector<Internal> internal;
  for (int f = 0; f < m.internal_faces(); ++f) {
    const int o = new_cell[m.owner[f]], n = new_cell[m.neighbour[f]];
    if (o != n) internal.push_back({std::min(o, n), std::max(o, n), f, o > n});
  }
  std::sort(internal.begin(), internal.end(), [](const Internal& x, const Internal& y) {
    return std::tie(x.owner, x.neighbour, x.face) < std::tie(y.owner, y.neighbour, y.face);
  });
  std::vector<int> point(m.points.size(), -1);
  auto add = [&](std::span<const int> face, bool turned) {
    std::vector<int> f(face.begin(), face.end());
    if (turned) std::reverse(f.begin() + 1, f.end());  // the same first point, the normal turned
    for (int& v : f) {
      if (point[v] < 0) point[v] = static_cast<int>(out.points.size()), out.points.push_back(m.points[v]);
      v = point[v];
    }
    out.faces.push_back(f);
  };
  for (const Internal& i : internal) {
    add(m.faces[i.face], i.turned);
    out.owner.push_back(i.owner);
    out.neighbour.push_back(i.neighbour);
  }
  for (PolyMesh::Patch patch : m.patches) {
    const int start = patch.start;
    patch.start = static_cast<int>(out.owner.size());
    for (int f = start; f < start + patch.size; ++f) {
      add(m.faces[f], false);
      out.owner.push_back(new_cell[m.owner[f]]);
    }
    out.patches.push_back(patch);
  }
  return out;
}

}  // namespace

JudgedQuality check_polyhedra(PolyhedralMesh& dual, std::vector<bool> judged, std::vector<int>* cell_points,
                             const Bed& bed, double d_ref, const std::string& what,
                             const std::filesystem::path& bad_cells_path) {
  const QualityGate& gate = kCheckMeshLimits;
  const auto judged_bad = [&](const CellQuality& q) {
    std::vector<int> bad;
    for (int c : q.bad_cells(gate, d_ref))
      if (judged.empty() || judged[c]) bad.push_back(c);
    return bad;
  };
  CellQuality q = cell_quality(dual);
  std::vector<int> bad = judged_bad(q);
  long merged = 0;
  if (!bad.empty()) {
    // Cells across a failing internal face, both judged, become one cell (union by the lower).
    std::vector<char> is_bad(dual.cells, 0);
    for (int c : bad) is_bad[c] = 1;
    std::vector<int> group(dual.cells);
    std::iota(group.begin(), group.end(), 0);
    const auto root = [&](int c) {
      while (group[c] != c) c = group[c] = group[group[c]];
      return c;
    };
    const std::vector<Eigen::Vector3d> centres = cell_geometry(dual).centres;
    for (int f = 0; f < dual.internal_faces(); ++f) {
      const int o = dual.owner[f], n = dual.neighbour[f];
      if (!(is_bad[o] || is_bad[n]) || !(judged.empty() || (judged[o] && judged[n]))) continue;
      if (!face_figures(dual.points, dual.faces[f], centres[o], &centres[n]).fails(gate)) continue;
      const int ro = root(o), rn = root(n);
      if (ro != rn) group[std::max(ro, rn)] = std::min(ro, rn), ++merged;
    }
    if (merged > 0) {
      const int old_cells = dual.cells;
      std::vector<int> new_cell(old_cells, -1), first(old_cells, -1);
      int cells = 0;
      for (int c = 0; c < old_cells; ++c) {
        const int r = root(c);
        if (first[r] < 0) first[r] = cells++;
        new_cell[c] = first[r];
      }
      dual = merged_cells(dual, new_cell, cells);
      std::vector<bool> kept(cells, judged.empty());
      std::vector<int> points(cell_points ? cells : 0);
      for (int c = old_cells - 1; c >= 0; --c) {  // each group keeps its first cell's point
        if (!judged.empty()) kept[new_cell[c]] = judged[c];
        if (cell_points) points[new_cell[c]] = (*cell_points)[c];
      }
      if (!judged.empty()) judged = std::move(kept);
      if (cell_points) *cell_points = std::move(points);
      q = cell_quality(dual);
      bad = judged_bad(q);
    }
  }
  JudgedQuality worst;
  worst.merged_cells = merged;
  worst.min_volume = worst.min_face_pyramid = std::numeric_limits<double>::max();
  for (int c = 0; c < dual.cells; ++c)
    if (judged.empty() || judged[c]) {
      ++worst.cells;
      worst.max_non_orthogonality_deg = std::max(worst.max_non_orthogonality_deg, q.non_orthogonality_deg[c]);
      worst.max_skewness = std::max(worst.max_skewness, q.skewness[c]);
      worst.max_aspect_ratio = std::max(worst.max_aspect_ratio, q.aspect_ratio[c]);
      worst.min_volume = std::min(worst.min_volume, q.volume[c]);
      worst.min_face_pyramid = std::min(worst.min_face_pyramid, q.min_face_pyramid[c]);
    }
  worst.failing_cells = static_cast<long>(bad.size());
  if (bad.empty()) {
    std::filesystem::remove(bad_cells_path);  // an earlier run's, which no longer describes the mesh
    return worst;
  }
  const DefectLocations where = locate_bad_cells(bed, dual, q, bad, bad_cells_path);
  const double d3 = d_ref * d_ref * d_ref;
  worst.failure = fmt::format(
      "{}: {} of {} cells fail checkMesh's limits (max non-orthogonality {:.1f} deg, limit {}; max skewness {:.2f}, "
      "limit {}; max aspect ratio {:.0f}, limit {}; min volume {:.2e} d^3, limit {:.0e}; smallest face pyramid "
      "{:.2e} d^3, limit {:.2e} (checkMesh's {:.0e} m^3)){}, most near {}; cells written to {}",
      what, bad.size(), worst.cells, worst.max_non_orthogonality_deg, gate.max_non_orthogonality_deg,
      worst.max_skewness, gate.max_skewness, worst.max_aspect_ratio, gate.max_aspect_ratio, worst.min_volume / d3,
      gate.min_volume_d3, worst.min_face_pyramid / d3, gate.min_face_pyramid_m3 / d3, gate.min_face_pyramid_m3,
      merged ? fmt::format(" after {} cells were merged with their neighbours across failing faces", merged) : "",
      where.summary, bad_cells_path.string());
  return worst;
}

nlohmann::json JudgedQuality::to_json(double d_ref) const {
  const double d3 = d_ref * d_ref * d_ref;
  return {{"cells", cells},
          {"merged_cells", merged_cells},
          {"ears_cut", ears_cut},
          {"failing_cells", failing_cells},
          {"failure", failure},
          {"max_non_orthogonality_deg", max_non_orthogonality_deg},
          {"max_skewness", max_skewness},
          {"max_aspect_ratio", max_aspect_ratio},
          {"min_volume_d3", min_volume / d3},
          {"min_face_pyramid_d3", min_face_pyramid / d3}};
}

JudgedQuality JudgedQuality::from_json(const nlohmann::json& j, double d_ref) {
  const double d3 = d_ref * d_ref * d_ref;
  JudgedQuality q;
  q.cells = j.at("cells").get<long>();
  q.merged_cells = j.at("merged_cells").get<long>();
  q.ears_cut = j.value("ears_cut", 0L);  // reports before 2026-11-29 (session 46) lack it
  q.failing_cells = j.at("failing_cells").get<long>();
  q.failure = j.at("failure").get<std::string>();
  q.max_non_orthogonality_deg = j.at("max_non_orthogonality_deg").get<double>();
  q.max_skewness = j.at("max_skewness").get<double>();
  q.max_aspect_ratio = j.at("max_aspect_ratio").get<double>();
  q.min_volume = j.at("min_volume_d3").get<double>() * d3;
  q.min_face_pyramid = j.at("min_face_pyramid_d3").get<double>() * d3;
  return q;
}

void JudgedQuality::add(const JudgedQuality& part) {
  cells += part.cells;
  merged_cells += part.merged_cells;
  ears_cut += part.ears_cut;
  failing_cells += part.failing_cells;
  max_non_orthogonality_deg = std::max(max_non_orthogonality_deg, part.max_non_orthogonality_deg);
  max_skewness = std::max(max_skewness, part.max_skewness);
  max_aspect_ratio = std::max(max_aspect_ratio, part.max_aspect_ratio);
  min_volume = std::min(min_volume, part.min_volume);
  min_face_pyramid = std::min(min_face_pyramid, part.min_face_pyramid);
  if (!part.failure.empty()) failure += (failure.empty() ? "" : "; ") + part.failure;
}

}  // namespace bedforge::meshing
