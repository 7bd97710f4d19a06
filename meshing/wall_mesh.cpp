#include "meshing/wall_mesh.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "meshing/primitives.hpp"
#include "meshing/spaced_points.hpp"

namespace bedforge::meshing {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using Fb = CGAL::Constrained_triangulation_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

double wrap_2pi(double a) {
  a = std::fmod(a, 2.0 * std::numbers::pi);
  return a < 0.0 ? a + 2.0 * std::numbers::pi : a;
}

double wrap_pi(double a) { return wrap_2pi(a + std::numbers::pi) - std::numbers::pi; }

bool inside_polygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i].y() > p.y()) != (poly[j].y() > p.y()) &&
        p.x() < (poly[j].x() - poly[i].x()) * (p.y() - poly[i].y()) / (poly[j].y() - poly[i].y()) + poly[i].x())
      in = !in;
  return in;
}

// The closed polygon moved outward by `offset` along its vertex normals, resampled at `spacing`.
std::vector<Eigen::Vector2d> offset_polygon(const std::vector<Eigen::Vector2d>& poly, double offset, double spacing,
                                            bool stagger) {
  const std::size_t n = poly.size();
  double area = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto &a = poly[i], &b = poly[(i + 1) % n];
    area += a.x() * b.y() - b.x() * a.y();
  }
  const double sense = area > 0.0 ? 1.0 : -1.0;  // outward normal of edge (dx, dy) is sense * (dy, -dx)
  std::vector<Eigen::Vector2d> moved;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e0 = (poly[i] - poly[(i + n - 1) % n]).normalized(), e1 = (poly[(i + 1) % n] - poly[i]).normalized();
    const Eigen::Vector2d normal = sense * Eigen::Vector2d(e0.y() + e1.y(), -e0.x() - e1.x()).normalized();
    moved.push_back(poly[i] + offset * normal);
  }
  return resample_loop(moved, spacing, stagger);
}

// Drops the vertices no triangle uses.
void compact(TriangleMesh& m) {
  std::vector<int> to(m.points.size(), -1);
  std::vector<Eigen::Vector3d> kept;
  for (auto& t : m.triangles)
    for (int& v : t) {
      if (to[v] < 0) to[v] = static_cast<int>(kept.size()), kept.push_back(m.points[v]);
      v = to[v];
    }
  m.points = std::move(kept);
}

}  // namespace

WallMesh wall_mesh(double R, double z0, double z1, double edge, const std::vector<WallHole>& holes, double growth,
                   bool outward, const std::string& patch) {
  const int n = ring_points(R, edge);
  const double step = 2.0 * std::numbers::pi * R / n, period = 2.0 * std::numbers::pi * R, margin = 3.0 * step;
  const int nz = 2 * std::max(1, static_cast<int>(std::ceil((z1 - z0) / (std::sqrt(3.0) * step))));
  auto row_z = [&](int k) { return k == nz ? z1 : z0 + (z1 - z0) * k / nz; };
  auto row_frame = [&](int k) { return Frame::along(Eigen::Vector3d(0.0, 0.0, row_z(k)), Eigen::Vector3d::UnitZ()); };
  const Eigen::Vector3d shift(period, 0.0, 0.0);

  std::vector<Eigen::Vector3d> points;  // 3D vertices
  std::vector<Eigen::Vector2d> uv;      // 2D sites: every vertex at s in [0, period), copies in the margins
  std::vector<int> vertex;              // site -> 3D vertex
  std::vector<int> copy;                // site -> 0 for the vertex itself, +1 or -1 for its copy at s +- period
  SpacedPoints spaced(step);            // the vertices at s in [0, period)
  auto fits = [&](const Eigen::Vector2d& q, double spacing) {
    const Eigen::Vector3d p(q.x(), q.y(), 0.0);
    return spaced.fits(p, spacing) && spaced.fits(p + shift, spacing) && spaced.fits(p - shift, spacing);
  };
  auto add_site = [&](const Eigen::Vector2d& q, int v, int shifted) {
    uv.push_back(q), vertex.push_back(v), copy.push_back(shifted);
  };
  // A vertex, its site, and its copy one period away when it lies within the margin of an end.
  auto add_vertex = [&](const Eigen::Vector3d& p, const Eigen::Vector2d& q, double spacing, bool copies) {
    points.push_back(p);
    const int v = static_cast<int>(points.size()) - 1;
    add_site(q, v, 0);
    spaced.add(Eigen::Vector3d(q.x(), q.y(), 0.0), spacing);
    if (copies && q.x() < margin) add_site(q + Eigen::Vector2d(period, 0.0), v, 1);
    if (copies && q.x() > period - margin) add_site(q - Eigen::Vector2d(period, 0.0), v, -1);
  };
  // The strip's ends (s = 0) along the lattice generator farthest from every hole's centre:
  // faces there are matched with their copies one period on, which is exact only where the
  // two triangulations agree, so keep holes away from it where the wall has room.
  std::vector<double> centres;
  for (const auto& hole : holes) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : hole.loop) mean += Eigen::Vector2d(p.x(), p.y()).normalized();
    centres.push_back(std::atan2(mean.y(), mean.x()));
  }
  int j_seam = 0;
  double clearest = -1.0;
  for (int j = 0; j < n && !centres.empty(); ++j) {
    double clearance = std::numbers::pi;
    for (double c : centres) clearance = std::min(clearance, std::abs(wrap_pi(2.0 * std::numbers::pi * j / n - c)));
    if (clearance > clearest) clearest = clearance, j_seam = j;
  }
  const double seam = 2.0 * std::numbers::pi * j_seam / n;
  // 1. Fixed vertices: the end rows and the hole loops; a hole is unrolled around its own
  // centre, so it stays one polygon even where it crosses theta = 0.
  for (int k : {0, nz})
    for (int j = 0; j < n; ++j)
      add_vertex(row_frame(k).to_world(on_circle(R, j, n, false, 0.0)),
                 Eigen::Vector2d(R * wrap_2pi(2.0 * std::numbers::pi * j / n - seam), row_z(k)), step, true);
  std::vector<std::vector<Eigen::Vector2d>> polygons;
  std::vector<std::vector<int>> loop_sites;
  std::vector<std::size_t> original;  // per hole, its polygon at offset 0
  for (const auto& hole : holes) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : hole.loop) mean += Eigen::Vector2d(p.x(), p.y()).normalized();
    const double centre = wrap_2pi(std::atan2(mean.y(), mean.x()) - seam);
    std::vector<Eigen::Vector2d> poly;
    for (const auto& p : hole.loop) {
      const Eigen::Vector2d q(R * (centre + wrap_pi(std::atan2(p.y(), p.x()) - seam - centre)), p.z());
      if (q.y() <= z0 + 0.5 * step || q.y() >= z1 - 0.5 * step)
        throw CutConflict("a hole in the wall reaches the inlet or outlet plane");
      poly.push_back(q);
      points.push_back(p);
      spaced.add(Eigen::Vector3d(wrap_2pi(q.x() / R) * R, q.y(), 0.0), std::min(hole.spacing, step));
    }
    const int first = static_cast<int>(points.size() - poly.size());
    double lo = poly[0].x(), hi = lo;
    for (const auto& q : poly) lo = std::min(lo, q.x()), hi = std::max(hi, q.x());
    original.push_back(polygons.size());  // offset 0 comes first
    for (double offset : {0.0, -period, period}) {
      if (offset != 0.0 && hi + offset < -margin) continue;
      if (offset != 0.0 && lo + offset > period + margin) continue;
      polygons.emplace_back(), loop_sites.emplace_back();
      for (std::size_t k = 0; k < poly.size(); ++k) {
        polygons.back().push_back(poly[k] + Eigen::Vector2d(offset, 0.0));
        loop_sites.back().push_back(static_cast<int>(uv.size()));
        add_site(polygons.back().back(), first + static_cast<int>(k), offset == 0.0 ? 0 : offset > 0.0 ? 1 : -1);
      }
    }
  }
  // Holes by their lowest z, so a point is tested against the few that can hold it.
  std::vector<std::array<double, 4>> boxes;  // s_min, s_max, z_min, z_max
  double tallest = 0.0;
  for (const auto& poly : polygons) {
    std::array<double, 4> box{poly[0].x(), poly[0].x(), poly[0].y(), poly[0].y()};
    for (const auto& q : poly) box = {std::min(box[0], q.x()), std::max(box[1], q.x()), std::min(box[2], q.y()), std::max(box[3], q.y())};
    boxes.push_back(box);
    tallest = std::max(tallest, box[3] - box[2]);
  }
  std::vector<std::size_t> by_z(polygons.size());
  std::iota(by_z.begin(), by_z.end(), 0);
  std::sort(by_z.begin(), by_z.end(), [&](std::size_t a, std::size_t b) { return boxes[a][2] < boxes[b][2]; });
  std::vector<double> z_low;
  for (std::size_t h : by_z) z_low.push_back(boxes[h][2]);
  auto in_hole = [&](const Eigen::Vector2d& q) {
    const auto first = std::lower_bound(z_low.begin(), z_low.end(), q.y() - tallest) - z_low.begin();
    for (auto k = first; k < static_cast<long>(z_low.size()) && z_low[k] <= q.y(); ++k) {
      const std::size_t h = by_z[k];
      if (q.x() >= boxes[h][0] && q.x() <= boxes[h][1] && q.y() <= boxes[h][3] && inside_polygon(polygons[h], q))
        return true;
    }
    return false;
  };
  auto try_add = [&](Eigen::Vector2d q, double spacing) {
    q.x() = R * wrap_2pi(q.x() / R);
    if (q.y() < z0 + 0.4 * spacing || q.y() > z1 - 0.4 * spacing) return;
    if (in_hole(q) || in_hole(q + Eigen::Vector2d(period, 0.0)) || !fits(q, spacing)) return;
    const double theta = seam + q.x() / R;
    add_vertex(Eigen::Vector3d(R * std::cos(theta), R * std::sin(theta), q.y()), q, spacing, true);
  };
  // 2. Rings graded away from the holes (around the first copy of each).
  std::vector<double> spacing;
  for (const auto& hole : holes) spacing.push_back(hole.spacing);
  graded_rings(spacing, step, growth, [&](std::size_t h, int ring, double offset, double next) {
    for (const auto& q : offset_polygon(polygons[original[h]], offset, next, ring % 2 == 1)) try_add(q, next);
  });
  // 3. The staggered lattice.
  for (int k = 1; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      try_add(Eigen::Vector2d(R * ((j + (k % 2 == 1 ? 0.5 : 0.0)) * 2.0 * std::numbers::pi / n - seam), row_z(k)), step);

  // 4. Constrained Delaunay triangulation of the strip; faces inside a hole go to `inside`.
  // Inserted row by row, back and forth, so each point is found from the previous one in a
  // few steps (hole loops come in bed order, which jumps about).
  std::vector<std::size_t> order(uv.size());
  std::iota(order.begin(), order.end(), 0);
  auto row = [&](std::size_t i) { return static_cast<long>(std::floor((uv[i].y() - z0) / step)); };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const long ra = row(a), rb = row(b);
    if (ra != rb) return ra < rb;
    return ra % 2 == 0 ? uv[a].x() < uv[b].x() : uv[a].x() > uv[b].x();
  });
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handle(uv.size());
  Cdt::Face_handle hint;
  for (std::size_t i : order) {
    handle[i] = cdt.insert(Kernel::Point_2(uv[i].x(), uv[i].y()), hint);
    handle[i]->info() = static_cast<int>(i);
    hint = handle[i]->face();
  }
  for (const auto& sites : loop_sites)
    for (std::size_t k = 0; k < sites.size(); ++k)
      cdt.insert_constraint(handle[sites[k]], handle[sites[(k + 1) % sites.size()]]);
  WallMesh out;
  out.outside.points = out.inside.points = points;
  for (auto f : cdt.finite_face_handles()) {
    std::array<int, 3> t;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    bool original = false, below = false;
    for (int k = 0; k < 3; ++k) {
      const int site = f->vertex(k)->info();
      t[k] = vertex[site];
      centroid += uv[site] / 3.0;
      original |= copy[site] == 0, below |= copy[site] < 0;
    }
    // Across the strip's ends the same face appears twice, one period apart: keep the one
    // with a vertex itself and none from the copies below s = 0 (exact, whatever the rounding).
    if (!original || below) continue;
    (in_hole(centroid) ? out.inside : out.outside).triangles.push_back(t);
  }
  for (TriangleMesh* m : {&out.outside, &out.inside}) {
    m->patch.assign(m->triangles.size(), 0);
    m->patches = {patch};
    orient_by(*m, [&](const Eigen::Vector3d& q) {
      const Eigen::Vector3d radial(q.x(), q.y(), 0.0);
      return outward ? radial : Eigen::Vector3d(-radial);
    });
    compact(*m);
  }
  return out;
}

}  // namespace bedforge::meshing
