#include "meshing/surface/wall_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>
#include <numbers>

#include "core/random.hpp"
#include "meshing/surface/planar_cdt.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

namespace {

double wrap_2pi(double a) {
  a = std::fmod(a, 2.0 * std::numbers::pi);
  return a < 0.0 ? a + 2.0 * std::numbers::pi : a;
}

double wrap_pi(double a) { return wrap_2pi(a + std::numbers::pi) - std::numbers::pi; }

}  // namespace

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> snap_holes_to_rings(std::vector<WallHole>& holes,
                                                                             const std::vector<double>& rings) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> moves;
  for (WallHole& hole : holes)
    for (double z : rings) {
      std::vector<Eigen::Vector3d>& loop = hole.loop;
      const std::size_t n = loop.size();
      auto move = [&](std::size_t k, Eigen::Vector3d to) {
        to.z() = z;
        moves.emplace_back(loop[k], to);
        loop[k] = to;
      };
      const double near = kRingSnap * hole.spacing;
      const auto [lowest, highest] = std::minmax_element(
          loop.begin(), loop.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
      if (n > 0 && !(lowest->z() < z && highest->z() > z)) {
        // On one side (or touching it): the near vertices away from the ring, to `near`.
        const double side = highest->z() > z ? 1.0 : -1.0;
        for (std::size_t k = 0; k < n; ++k)
          if (side * (loop[k].z() - z) < near) {
            Eigen::Vector3d to = loop[k];
            to.z() = z + side * near;
            moves.emplace_back(loop[k], to);
            loop[k] = to;
          }
        continue;
      }
      // Vertices near the ring onto it (straight down or up), then the nearer end of each edge
      // still crossing it along that edge.
      for (std::size_t k = 0; k < n; ++k)
        if (loop[k].z() != z && std::abs(loop[k].z() - z) < near) move(k, loop[k]);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t l = (k + 1) % n;
        const double a = loop[k].z() - z, b = loop[l].z() - z;
        if (!(a * b < 0.0)) continue;
        const Eigen::Vector3d at = loop[k] + a / (a - b) * (loop[l] - loop[k]);
        move(std::abs(a) <= std::abs(b) ? k : l, at);
      }
    }
  return moves;
}

namespace {

// Equal parts of an interval `step` long so that each is about `wanted` (m) long: a quarter over
// is let pass, so a spacing just under the step does not halve it.
int parts_for(double step, double wanted) { return std::max(1, static_cast<int>(std::ceil(step / wanted - 0.25))); }

}  // namespace

EndRow end_row(const Frame& frame, double R, int n, const std::vector<int>& parts) {
  EndRow row;
  const double step = 2.0 * std::numbers::pi * R / n;
  for (int j = 0; j < n; ++j) {
    const int m = parts.empty() ? 1 : parts[j];
    for (int i = 0; i < m; ++i) {
      // theta as on_circle computes it and the angle as the strip's sites did: both rows and
      // strips stay what they were bit for bit where nothing is divided.
      const double t = j + static_cast<double>(i) / m, theta = t * (2.0 * std::numbers::pi / n);
      row.points.push_back(frame.to_world({R * std::cos(theta), R * std::sin(theta), 0.0}));
      row.angles.push_back(2.0 * std::numbers::pi * t / n);
      row.spacing.push_back(step / m);
    }
  }
  return row;
}

std::vector<int> end_row_parts(double R, int n, double z0, double z1, const SpacingField& field) {
  std::vector<int> parts(n, 1);
  if (!field) return parts;
  const double step = 2.0 * std::numbers::pi * R / n;
  for (int j = 0; j < n; ++j) {
    const double theta = (j + 0.5) * (2.0 * std::numbers::pi / n);
    for (double z : {z0, z1}) {
      const double wanted = field.at({R * std::cos(theta), R * std::sin(theta), z});
      parts[j] = std::max(parts[j], parts_for(step, wanted));
    }
  }
  return parts;
}

WallMesh wall_mesh(double R, double z0, double z1, double edge, const std::vector<WallHole>& holes, double growth,
                   bool outward, const std::string& patch, const SpacingField& field, const std::vector<double>& rings,
                   const std::vector<int>& row_parts) {
  const int n = ring_points(R, edge);
  // Sites lie on a dyadic grid in s whose step divides the period, so a site's copy one period
  // on is its exact translate: the exact predicates then see the two ends of the strip alike
  // (with rounded copies, cocircular hole loops were triangulated differently at each end).
  const double quantum = std::ldexp(1.0, std::ilogb(2.0 * std::numbers::pi * R) - 36);
  auto on_grid = [quantum](Eigen::Vector2d q) {
    q.x() = std::round(q.x() / quantum) * quantum;
    return q;
  };
  const double step = 2.0 * std::numbers::pi * R / n, period = on_grid({2.0 * std::numbers::pi * R, 0.0}).x(),
               margin = 3.0 * step;
  // The lattice's rows: the strip between its ends and rings, each part in an even number of
  // rows about sqrt(3)/2 step apart, every other one shifted by half a step. The ends and rings
  // are then unshifted rows with shifted rows beside them: a ring between unshifted rows made
  // rectangles of four cocircular vertices, whose diagonal HXT's Delaunay took the other way, and
  // recovering those facets cost it 3 to 4 times its memory.
  struct Row {
    double z;
    // Its vertices' distance to those of the rows beside it: with the step as their spacing,
    // rows nearer than 0.62 step (short parts) lost every other row to the spacing test and
    // left rectangles of cocircular points again.
    double spacing;
    bool shifted, fixed;  // fixed: an end or a ring, whose vertices are added on their own
  };
  std::vector<double> bounds{z0};
  bounds.insert(bounds.end(), rings.begin(), rings.end());
  std::sort(bounds.begin() + 1, bounds.end());
  bounds.push_back(z1);
  std::vector<Row> rows;
  for (std::size_t b = 0; b + 1 < bounds.size(); ++b) {
    const double lo = bounds[b], hi = bounds[b + 1];
    const int nz = 2 * std::max(1, static_cast<int>(std::ceil((hi - lo) / (std::sqrt(3.0) * step))));
    const double spacing = std::min(step, std::hypot((hi - lo) / nz, 0.5 * step));
    for (int k = 0; k < nz; ++k) rows.push_back({k == 0 ? lo : lo + (hi - lo) * k / nz, spacing, k % 2 == 1, k == 0});
  }
  rows.push_back({z1, step, false, true});
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
  auto add_vertex = [&](const Eigen::Vector3d& p, const Eigen::Vector2d& at, double spacing, bool copies) {
    const Eigen::Vector2d q = on_grid(at);
    points.push_back(p);
    const int v = static_cast<int>(points.size()) - 1;
    add_site(q, v, 0);
    spaced.add(Eigen::Vector3d(q.x(), q.y(), 0.0), spacing);
    if (copies && q.x() < margin) add_site(q + Eigen::Vector2d(period, 0.0), v, 1);
    if (copies && q.x() > period - margin) add_site(q - Eigen::Vector2d(period, 0.0), v, -1);
  };
  // The strip's ends (s = 0) along the lattice generator farthest from every hole's centre:
  // faces there are matched with their copies one period on, so keep holes away from it where
  // the wall has room.
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
  for (double z : {z0, z1}) {
    const EndRow row = end_row(Frame::along(Eigen::Vector3d(0.0, 0.0, z), Eigen::Vector3d::UnitZ()), R, n, row_parts);
    for (std::size_t k = 0; k < row.points.size(); ++k)
      add_vertex(row.points[k], Eigen::Vector2d(R * wrap_2pi(row.angles[k] - seam), z), row.spacing[k], true);
  }
  std::vector<std::vector<Eigen::Vector2d>> polygons;
  std::vector<std::vector<int>> loop_sites;
  std::vector<std::size_t> original;  // per hole, its polygon at offset 0
  std::vector<double> polygon_spacing;  // per polygon, its hole's
  for (const auto& hole : holes) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : hole.loop) mean += Eigen::Vector2d(p.x(), p.y()).normalized();
    const double centre = wrap_2pi(std::atan2(mean.y(), mean.x()) - seam);
    std::vector<Eigen::Vector2d> poly;
    for (const auto& p : hole.loop) {
      const Eigen::Vector2d q = on_grid({R * (centre + wrap_pi(std::atan2(p.y(), p.x()) - seam - centre)), p.z()});
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
      polygons.emplace_back(), loop_sites.emplace_back(), polygon_spacing.push_back(std::min(hole.spacing, step));
      for (std::size_t k = 0; k < poly.size(); ++k) {
        polygons.back().push_back(poly[k] + Eigen::Vector2d(offset, 0.0));
        loop_sites.back().push_back(static_cast<int>(uv.size()));
        add_site(polygons.back().back(), first + static_cast<int>(k), offset == 0.0 ? 0 : offset > 0.0 ? 1 : -1);
      }
    }
  }
  const PolygonIndex hole_index(polygons);
  auto in_hole = [&](const Eigen::Vector2d& q) { return hole_index.contains(q); };
  // 1b. Rings: a row of end-row vertices at each height, less those in or beside a hole, joined
  // by constraints to each other and to the holes' vertices on the ring (snap_holes_to_rings).
  // The wall's triangles then end on the ring from both sides, whatever else is meshed there.
  std::vector<std::array<int, 2>> ring_constraints;
  std::unordered_map<int, std::vector<int>> sites_of;  // vertex -> its sites, for those on a ring
  for (double z : rings) {
    if (!(z > z0 + 0.5 * step && z < z1 - 0.5 * step))
      throw std::invalid_argument(fmt::format("wall_mesh: ring at z = {} m outside ({}, {})", z, z0, z1));
    // The ring's vertices as sites in [0, period), in order along it.
    std::vector<std::pair<double, int>> along;
    std::vector<Eigen::Vector2d> on_ring;  // the holes' vertices on it
    for (std::size_t h = 0; h < holes.size(); ++h)
      for (std::size_t k = 0; k < holes[h].loop.size(); ++k) {
        if (holes[h].loop[k].z() != z) continue;
        const int v = vertex[loop_sites[original[h]][k]];
        if (sites_of.count(v)) continue;
        for (std::size_t site = 0; site < uv.size(); ++site)
          if (vertex[site] == v) sites_of[v].push_back(static_cast<int>(site));
        const Eigen::Vector2d q = uv[loop_sites[original[h]][k]];
        on_ring.push_back(q);
        along.emplace_back(R * wrap_2pi(q.x() / R), v);
      }
    // The holes' vertices near the ring, with their loops' spacing: the ring's points are
    // graded towards them as the rings around a hole are (a loop vertex just off the ring would
    // otherwise make a needle with two ring points an edge apart).
    std::vector<std::pair<Eigen::Vector2d, double>> near;
    for (std::size_t k = 0; k < polygons.size(); ++k)
      for (const auto& q : polygons[k])
        if (std::abs(q.y() - z) < step) near.emplace_back(q, polygon_spacing[k]);
    // The holes' loop edges along the ring (both ends snapped onto it): a ring point between
    // their ends would lie on the hole's edge, a vertex of the wall's triangles but not of the
    // hole's (on a = 14, N = 1e4 at 0.033 d where contacts meet, the cut of that ring found the
    // surface open there).
    std::vector<std::pair<double, double>> along_holes;
    for (const auto& poly : polygons)
      for (std::size_t k = 0; k < poly.size(); ++k) {
        const Eigen::Vector2d &a = poly[k], &b = poly[(k + 1) % poly.size()];
        if (a.y() == z && b.y() == z) along_holes.emplace_back(std::min(a.x(), b.x()), std::max(a.x(), b.x()));
      }
    auto on_a_hole_edge = [&](double x) {
      for (const auto& [lo, hi] : along_holes)
        for (double shift : {0.0, period, -period})
          if (x + shift > lo && x + shift < hi) return true;
      return false;
    };
    for (int j = 0; j < n; ++j) {
      // The interval from ring point j to j + 1 in m equal parts, m from the spacing wanted
      // at its middle: alike in every window, whose holes near the ring are the same.
      const double s_mid = R * (2.0 * std::numbers::pi * (j + 0.5) / n - seam);
      double wanted = step;
      for (const auto& [q, spacing] : near) {
        const double ds = std::abs(wrap_pi((q.x() - s_mid) / R)) * R, dz = q.y() - z;
        wanted = std::min(wanted, spacing + (growth - 1.0) * std::max(0.0, std::hypot(ds, dz) - 0.5 * step));
      }
      const int m = parts_for(step, wanted);
      for (int i = 0; i < m; ++i) {
        const double t = static_cast<double>(i) / m, angle = 2.0 * std::numbers::pi * (j + t) / n;
        const Eigen::Vector2d q = on_grid({R * wrap_2pi(angle - seam), z});
        bool clear = !in_hole(q) && !in_hole(q + Eigen::Vector2d(period, 0.0)) &&
                     !in_hole(q - Eigen::Vector2d(period, 0.0)) && !on_a_hole_edge(q.x());
        for (const Eigen::Vector2d& h : on_ring)
          clear = clear && std::abs(wrap_pi((q.x() - h.x()) / R)) * R >= 0.5 * step / m;
        if (!clear) continue;
        const std::size_t first = uv.size();
        add_vertex(Eigen::Vector3d(R * std::cos(angle), R * std::sin(angle), z), q, step / m, true);
        const int v = vertex[first];
        for (std::size_t site = first; site < uv.size(); ++site) sites_of[v].push_back(static_cast<int>(site));
        along.emplace_back(q.x(), v);
      }
    }
    std::sort(along.begin(), along.end());
    // Vertex v's site at about s = x (its own, or its copy a period on or back); -1 if none.
    auto site_at = [&](int v, double x) {
      for (int site : sites_of.at(v))
        if (std::abs(uv[site].x() - x) < 0.25 * period) return site;
      return -1;
    };
    for (std::size_t k = 0; k < along.size(); ++k) {
      const bool wrap = k + 1 == along.size();
      const auto [sa, a] = along[k];
      const double sb = wrap ? along[0].first + period : along[k + 1].first;
      const int b = along[wrap ? 0 : k + 1].second;
      const Eigen::Vector2d mid(0.5 * (sa + sb), z);
      if (in_hole(mid) || in_hole(mid - Eigen::Vector2d(period, 0.0)) || in_hole(mid + Eigen::Vector2d(period, 0.0)))
        continue;  // across a hole
      // The segment and its copies a period on and back, where both its ends have one.
      for (double shift : {-period, 0.0, period}) {
        const int from = site_at(a, sa + shift), to = site_at(b, sb + shift);
        if (from >= 0 && to >= 0) ring_constraints.push_back({from, to});
        else if (shift == 0.0)
          throw CutConflict(fmt::format("the wall's ring at z = {} m cannot be joined across the strip's seam", z));
      }
      // Free vertices keep off the constraint as off the ring's points; along a whole step, the
      // shifted row beside it (0.44 step away at the least) is let in.
      const double length = sb - sa;
      for (double t : {0.25, 0.5, 0.75})
        spaced.add(Eigen::Vector3d(R * wrap_2pi((sa + t * length) / R), z, 0.0),
                   length < 0.99 * step ? length : 0.25 * step);
    }
  }
  auto on_wall = [&](const Eigen::Vector2d& q) {
    const double theta = seam + q.x() / R;
    return Eigen::Vector3d(R * std::cos(theta), R * std::sin(theta), q.y());
  };
  // The spacing asked for at q: `spacing`, or less where the field asks for less.
  auto try_add = [&](Eigen::Vector2d q, double spacing) {
    q.x() = R * wrap_2pi(q.x() / R);
    if (field) spacing = std::min(spacing, field.at(on_wall(q)));
    if (q.y() < z0 + 0.4 * spacing || q.y() > z1 - 0.4 * spacing) return;
    if (in_hole(q) || in_hole(q + Eigen::Vector2d(period, 0.0)) || !fits(q, spacing)) return;
    add_vertex(on_wall(q), q, spacing, true);
  };
  // 2. Rings graded away from the holes (around the first copy of each).
  std::vector<double> spacing;
  for (const auto& hole : holes) spacing.push_back(hole.spacing);
  graded_rings(spacing, step, growth, [&](std::size_t h, int ring, double offset, double next) {
    for (const auto& q : offset_polygon(polygons[original[h]], offset, next, ring % 2 == 1)) try_add(q, next);
  });
  // 3. The staggered lattice: of the field's finest spacing where it asks for less than the
  // step (finest first), then of the step.
  if (field && field.finest < step) {
    const int nf = static_cast<int>(std::ceil(period / field.finest));
    const double row = std::sqrt(3.0) / 2.0 * field.finest;
    offer_finest_first<Eigen::Vector2d>(
        field, step,
        [&](const auto& visit) {
          for (int k = 1; z0 + k * row < z1; ++k)
            for (int j = 0; j < nf; ++j) visit(Eigen::Vector2d(period * (j + 0.5 * (k % 2)) / nf, z0 + k * row));
        },
        on_wall, try_add);
  }
  for (const Row& row : rows)
    if (!row.fixed)
      for (int j = 0; j < n; ++j)
        try_add(Eigen::Vector2d(R * ((j + (row.shifted ? 0.5 : 0.0)) * 2.0 * std::numbers::pi / n - seam), row.z),
                row.spacing);

  // 4. Constrained Delaunay triangulation of the strip; faces inside a hole go to `inside`.
  Cdt cdt;
  const std::vector<Cdt::Vertex_handle> handle = insert_in_rows(cdt, uv, step);
  for (const auto& sites : loop_sites)
    for (std::size_t k = 0; k < sites.size(); ++k)
      cdt.insert_constraint(handle[sites[k]], handle[sites[(k + 1) % sites.size()]]);
  for (const auto& [a, b] : ring_constraints) cdt.insert_constraint(handle[a], handle[b]);
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
    drop_unused_points(*m);
  }
  return out;
}

WallMesh plane_mesh(const Frame& f, const std::vector<std::vector<Eigen::Vector3d>>& boundary, double edge,
                    const std::vector<WallHole>& holes, double growth, bool along_w, const std::string& patch,
                    const SpacingField& field) {
  auto local = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d((p - f.origin).dot(f.u), (p - f.origin).dot(f.v)); };
  std::vector<Eigen::Vector3d> points;  // 3D vertices, one per site
  std::vector<Eigen::Vector2d> uv;      // their sites
  SpacedPoints spaced(edge);
  auto add_vertex = [&](const Eigen::Vector3d& p, const Eigen::Vector2d& q, double spacing) {
    points.push_back(p), uv.push_back(q);
    spaced.add(Eigen::Vector3d(q.x(), q.y(), 0.0), spacing);
  };
  // 1. Fixed vertices: the boundary loops (with samples between their vertices, so nothing is
  // placed too close to a boundary edge) and the hole loops.
  std::vector<std::vector<Eigen::Vector2d>> outline, polygons;
  std::vector<std::vector<int>> loops;  // constrained loops, as site indices
  for (const auto& loop : boundary) {
    outline.emplace_back(), loops.emplace_back();
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const Eigen::Vector2d a = local(loop[k]), b = local(loop[(k + 1) % loop.size()]);
      const double spacing = std::min(edge, (b - a).norm());
      outline.back().push_back(a);
      loops.back().push_back(static_cast<int>(uv.size()));
      add_vertex(loop[k], a, spacing);
      for (double t : {0.25, 0.5, 0.75}) spaced.add(Eigen::Vector3d(a.x() + t * (b.x() - a.x()), a.y() + t * (b.y() - a.y()), 0.0), spacing);
    }
  }
  auto in_region = [&](const Eigen::Vector2d& q) {
    if (!inside_polygon(outline[0], q)) return false;
    for (std::size_t k = 1; k < outline.size(); ++k)
      if (inside_polygon(outline[k], q)) return false;
    return true;
  };
  for (const auto& hole : holes) {
    polygons.emplace_back(), loops.emplace_back();
    const double spacing = std::min(hole.spacing, edge);
    for (std::size_t k = 0; k < hole.loop.size(); ++k) {
      const Eigen::Vector2d q = local(hole.loop[k]), next = local(hole.loop[(k + 1) % hole.loop.size()]);
      if (!in_region(q)) throw CutConflict(fmt::format("a hole (particle {}) reaches the edge of the {}", hole.particle, patch));
      polygons.back().push_back(q);
      loops.back().push_back(static_cast<int>(uv.size()));
      add_vertex(hole.loop[k], q, spacing);
      // Samples every half spacing along an edge longer than the loop's spacing (a plane cut's
      // loops are uneven), or a site could land a hair beside its middle: a sliver of 1 deg on
      // a = 5's seed-3 slice (docs/findings.md, 2026-12-01).
      const int parts = static_cast<int>(std::ceil((next - q).norm() / (0.5 * spacing)));
      if (parts > 2)
        for (int j = 1; j < parts; ++j) {
          const Eigen::Vector2d at = q + (next - q) * (static_cast<double>(j) / parts);
          spaced.add(Eigen::Vector3d(at.x(), at.y(), 0.0), spacing);
        }
    }
  }
  const PolygonIndex hole_index(polygons);
  // Free sites move by up to kBreakCocircular / 2 of their spacing: the lattices and rings below
  // hold four points on a circle again and again (see kBreakCocircular).
  Rng nudge(1);
  auto try_add = [&](const Eigen::Vector2d& lattice, double spacing) {
    const Eigen::Vector2d q = lattice + kBreakCocircular * spacing * Eigen::Vector2d(nudge.uniform() - 0.5, nudge.uniform() - 0.5);
    const Eigen::Vector3d s(q.x(), q.y(), 0.0);
    if (field) spacing = std::min(spacing, field.at(f.to_world(s)));
    if (!in_region(q) || hole_index.contains(q) || !spaced.fits(s, spacing)) return;
    add_vertex(f.to_world(s), q, spacing);
  };
  // 2. The field's seeds, then rings graded away from the holes.
  for (const auto& [p, s] : field.seeds_finest_first()) try_add(local(p), s);
  std::vector<double> spacing;
  for (const auto& hole : holes) spacing.push_back(hole.spacing);
  graded_rings(spacing, edge, growth, [&](std::size_t h, int ring, double offset, double next) {
    for (const auto& q : offset_polygon(polygons[h], offset, next, ring % 2 == 1)) try_add(q, next);
  });
  // 3. The staggered lattice over the outer loop's bounding box: of the field's finest spacing
  // where it asks for less than the edge (finest first), then of the edge.
  Eigen::Vector2d lo = outline[0][0], hi = lo;
  for (const auto& q : outline[0]) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  auto staggered = [&](double step, const std::function<void(const Eigen::Vector2d&)>& visit) {
    const double row = std::sqrt(3.0) / 2.0 * step;
    for (int k = 0; lo.y() + k * row <= hi.y(); ++k)
      for (int j = 0; lo.x() + (j + 0.5 * (k % 2)) * step <= hi.x(); ++j)
        visit(Eigen::Vector2d(lo.x() + (j + 0.5 * (k % 2)) * step, lo.y() + k * row));
  };
  if (field && field.finest < edge)
    offer_finest_first<Eigen::Vector2d>(
        field, edge, [&](const auto& visit) { staggered(field.finest, visit); },
        [&](const Eigen::Vector2d& q) { return f.to_world(Eigen::Vector3d(q.x(), q.y(), 0.0)); }, try_add);
  staggered(edge, [&](const Eigen::Vector2d& q) { try_add(q, edge); });

  // 4. Constrained Delaunay triangulation. A face is in the region when one constraint lies
  // between it and the outside (counted by a flood fill that stops at constraints, not by where
  // its centroid falls: a sliver between three nearly collinear loop vertices outside a
  // non-convex boundary has its centroid on the boundary); behind a second one it is in a hole
  // (to `inside`) or beyond an inner boundary.
  Cdt cdt;
  const std::vector<Cdt::Vertex_handle> handle = insert_in_rows(cdt, uv, edge);
  for (const auto& loop : loops)
    for (std::size_t k = 0; k < loop.size(); ++k) cdt.insert_constraint(handle[loop[k]], handle[loop[(k + 1) % loop.size()]]);
  std::map<Cdt::Face_handle, int> depth;
  std::vector<Cdt::Edge> border;
  auto flood = [&](Cdt::Face_handle start, int level) {
    std::vector<Cdt::Face_handle> stack{start};
    while (!stack.empty()) {
      const Cdt::Face_handle fh = stack.back();
      stack.pop_back();
      if (!depth.emplace(fh, level).second) continue;
      for (int i = 0; i < 3; ++i)
        if (!depth.count(fh->neighbor(i))) (cdt.is_constrained({fh, i}) ? border.push_back({fh, i}) : stack.push_back(fh->neighbor(i)));
    }
  };
  flood(cdt.infinite_face(), 0);
  for (std::size_t b = 0; b < border.size(); ++b) {
    const Cdt::Face_handle behind = border[b].first->neighbor(border[b].second);
    if (!depth.count(behind)) flood(behind, depth.at(border[b].first) + 1);
  }
  WallMesh out;
  out.outside.points = out.inside.points = points;
  for (auto fh : cdt.finite_face_handles()) {
    std::array<int, 3> t;
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) {
      t[k] = fh->vertex(k)->info();
      centroid += uv[t[k]] / 3.0;
    }
    const int level = depth.at(fh);
    if (level == 1) out.outside.triangles.push_back(t);
    else if (level == 2 && hole_index.contains(centroid)) out.inside.triangles.push_back(t);
  }
  for (TriangleMesh* m : {&out.outside, &out.inside}) {
    m->patch.assign(m->triangles.size(), 0);
    m->patches = {patch};
    orient_by(*m, [&](const Eigen::Vector3d&) { return along_w ? f.w : Eigen::Vector3d(-f.w); });
    drop_unused_points(*m);
  }
  return out;
}

}  // namespace bedforge::meshing
