#include "meshing/surface_checks.hpp"

#include <fmt/format.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <execution>
#include <stdexcept>
#include <tuple>

namespace bedforge::meshing {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

namespace {

// `m` as a CGAL mesh, face k = triangle k; false when a triangle would make an edge or vertex
// non-manifold (CGAL refuses it, and the faces after it are not added).
bool to_cgal(const TriangleMesh& m, Mesh& mesh) {
  mesh.reserve(m.points.size(), 3 * m.triangles.size() / 2, m.triangles.size());
  for (const auto& p : m.points) mesh.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z()));
  for (const auto& t : m.triangles)
    if (mesh.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]), Mesh::Vertex_index(t[2])) == Mesh::null_face())
      return false;
  return true;
}

// The faces SelfIntersectionTest::by_pieces leaves to CGAL's test (the argument is in the header):
// every face of a piece not on its sphere, and the faces of a sphere piece near another piece
// that can reach it. Sweeping every face's box costs as much as CGAL's whole test, so the sweep
// is over units instead: each sphere piece whole (the box of its ball), the other pieces cut by a
// grid of cells about four of their edges wide. A sphere face is left when its box meets a unit
// that meets its sphere's: the box of a cell's faces, or the ball of a sphere piece whose ball is
// not apart from its own.
std::vector<Mesh::Face_index> faces_left_by_pieces(const TriangleMesh& m, const std::vector<SurfacePiece>& pieces) {
  const std::size_t n = m.triangles.size();
  // The ball that holds a sphere piece: its radius, plus what rounding the vertices to the 12
  // significant digits of fluid.stl (round_to_ascii_stl) may move them, far from the origin too.
  auto reach = [](const SurfacePiece& p) { return p.radius * (1.0 + 1e-9) + 2e-11 * (p.centre.norm() + p.radius); };
  auto box_of = [&m](std::size_t t) {
    CGAL::Bbox_3 b;
    for (int v : m.triangles[t]) b += CGAL::Bbox_3(m.points[v].x(), m.points[v].y(), m.points[v].z(), m.points[v].x(),
                                                   m.points[v].y(), m.points[v].z());
    return b;
  };
  // Step 1: the sphere pieces the argument may take (every vertex on the sphere), and the units:
  // faces members[first, last) in `box`.
  struct Unit {
    std::size_t piece, first, last;
    CGAL::Bbox_3 box;
  };
  std::vector<char> convex(pieces.size(), 0);
  std::vector<Unit> units;
  std::vector<std::uint32_t> members;
  members.reserve(n);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;  // (cell key, face) of one piece
  std::size_t covered = 0;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const SurfacePiece& p = pieces[k];
    if (p.first != covered || p.last < p.first || p.last > n)
      throw std::invalid_argument("check_surface: the pieces do not cover the triangles once, in order");
    covered = p.last;
    bool on = p.on_sphere;
    const double slack = reach(p) - p.radius;
    for (std::size_t t = p.first; t < p.last && on; ++t)
      for (int v : m.triangles[t]) on = on && std::abs((m.points[v] - p.centre).norm() - p.radius) <= slack;
    convex[k] = on;
    if (on) {
      const double r = reach(p);
      units.push_back({k, members.size(), members.size() + (p.last - p.first),
                       CGAL::Bbox_3(p.centre.x() - r, p.centre.y() - r, p.centre.z() - r, p.centre.x() + r,
                                    p.centre.y() + r, p.centre.z() + r)});
      for (std::size_t t = p.first; t < p.last; ++t) members.push_back(static_cast<std::uint32_t>(t));
      continue;
    }
    if (p.first == p.last) continue;
    double edges = 0.0;
    for (std::size_t t = p.first; t < p.last; ++t) edges += (m.points[m.triangles[t][1]] - m.points[m.triangles[t][0]]).norm();
    const double h = 4.0 * edges / static_cast<double>(p.last - p.first);
    const Eigen::Vector3d origin = m.points[m.triangles[p.first][0]];
    cells.clear();
    for (std::size_t t = p.first; t < p.last; ++t) {
      const Eigen::Vector3d c = (m.points[m.triangles[t][0]] + m.points[m.triangles[t][1]] + m.points[m.triangles[t][2]]) / 3.0;
      std::uint64_t key = 0;
      for (int i = 0; i < 3; ++i)  // 21 bits a coordinate: 2e6 cells each way, far more than a piece spans
        key = key << 21 | (static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor((c[i] - origin[i]) / h)) + (1 << 20)) & 0x1fffff);
      cells.emplace_back(key, static_cast<std::uint32_t>(t));
    }
    std::sort(cells.begin(), cells.end());
    for (std::size_t i = 0, j; i < cells.size(); i = j) {
      Unit u{k, members.size(), 0, CGAL::Bbox_3()};
      for (j = i; j < cells.size() && cells[j].first == cells[i].first; ++j) {
        members.push_back(cells[j].second);
        u.box += box_of(cells[j].second);
      }
      u.last = members.size();
      units.push_back(u);
    }
  }
  if (covered != n) throw std::invalid_argument("check_surface: the pieces do not cover the triangles once, in order");
  // Step 2: the pairs (sphere unit, unit of another piece that can reach it), by a sweep of the units' boxes.
  using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t, CGAL::Box_intersection_d::ID_FROM_BOX_ADDRESS>;
  std::vector<Box> boxes;
  boxes.reserve(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) boxes.emplace_back(units[u].box, u);
  std::vector<const Box*> ptr;
  for (const Box& b : boxes) ptr.push_back(&b);
  std::vector<std::pair<std::size_t, std::size_t>> near;  // (sphere unit, other unit)
  auto ball = [&](const Unit& u) -> const SurfacePiece& { return pieces[u.piece]; };
  CGAL::box_self_intersection_d(ptr.begin(), ptr.end(), [&](const Box* a, const Box* b) {
    const Unit &u = units[a->info()], &w = units[b->info()];
    if (u.piece == w.piece) return;  // a sphere by the argument; any other piece is tested whole
    const bool cu = convex[u.piece], cw = convex[w.piece];
    if (cu && cw && (ball(u).centre - ball(w).centre).norm() > reach(ball(u)) + reach(ball(w))) return;
    if (cu) near.emplace_back(a->info(), b->info());
    if (cw) near.emplace_back(b->info(), a->info());
  });
  // Step 3: the faces left: every face of the other pieces; of a sphere, those whose box meets
  // a near cell's box or a near sphere's ball.
  std::vector<char> left(n, 0);
  for (const Unit& u : units)
    if (!convex[u.piece])
      for (std::size_t i = u.first; i < u.last; ++i) left[members[i]] = 1;
  std::sort(near.begin(), near.end());
  auto reaches = [&](const CGAL::Bbox_3& b, const Unit& w) {
    if (!CGAL::do_overlap(b, w.box)) return false;
    if (!convex[w.piece]) return true;
    const SurfacePiece& s = pieces[w.piece];
    double gap2 = 0.0;  // squared distance from the ball's centre to the box
    for (int k = 0; k < 3; ++k) gap2 += std::pow(std::max({b.min(k) - s.centre[k], 0.0, s.centre[k] - b.max(k)}), 2);
    return gap2 <= std::pow(reach(s), 2);
  };
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t k = 0; k < near.size(); ++k) {
    if (k > 0 && near[k - 1].first == near[k].first) continue;  // each sphere unit by one thread, all its pairs
    const Unit& u = units[near[k].first];
    for (std::size_t i = u.first; i < u.last; ++i) {
      const std::size_t t = members[i];
      const CGAL::Bbox_3 b = box_of(t);
      for (std::size_t j = k; j < near.size() && near[j].first == near[k].first && !left[t]; ++j)
        left[t] = reaches(b, units[near[j].second]);
    }
  }
  std::vector<Mesh::Face_index> out;
  for (std::size_t t = 0; t < n; ++t)
    if (left[t]) out.emplace_back(static_cast<Mesh::size_type>(t));
  return out;
}

const char* test_name(SelfIntersectionTest t) {
  return t == SelfIntersectionTest::all_pairs ? "all pairs" : t == SelfIntersectionTest::by_pieces ? "by pieces" : "not run";
}

}  // namespace

nlohmann::json SurfaceCheck::to_json() const {
  const bool ran = self_intersection_test != SelfIntersectionTest::skip;
  return {{"manifold", manifold},
          {"closed", closed},
          {"self_intersections", ran ? nlohmann::json(self_intersecting) : nlohmann::json("not checked")},
          {"self_intersection_test", test_name(self_intersection_test)},
          {"triangles_tested_pairwise", triangles_tested_pairwise},
          {"enclosed_volume_m3", volume},
          {"defective_edges", defects.size()}};
}

SurfaceCheck check_surface(const TriangleMesh& m, SelfIntersectionTest test, const std::vector<SurfacePiece>& pieces) {
  SurfaceCheck out;
  // Step 0: every edge used once in each direction. Each directed edge a -> b as one number,
  // (smaller end, larger end, direction), sorted on every core so that an edge's uses are
  // adjacent (a hash map of 27 M edges at N = 1e4 took gigabytes and a malloc per edge).
  if (m.points.size() > std::size_t{1} << 31) throw std::invalid_argument("check_surface: more than 2^31 vertices");
  std::vector<std::uint64_t> half(3 * m.triangles.size());
#pragma omp parallel for schedule(static)
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = static_cast<std::uint32_t>(m.triangles[t][k]);
      const std::uint64_t b = static_cast<std::uint32_t>(m.triangles[t][(k + 1) % 3]);
      half[3 * t + k] = std::min(a, b) << 33 | std::max(a, b) << 1 | (a > b ? 1 : 0);
    }
  std::sort(std::execution::par, half.begin(), half.end());
  for (std::size_t i = 0, j = 0; i < half.size(); i = j) {
    int back = 0;
    for (j = i; j < half.size() && half[j] >> 1 == half[i] >> 1; ++j) back += static_cast<int>(half[j] & 1);
    const int forward = static_cast<int>(j - i) - back;
    if (forward != 1 || back != 1)
      out.defects.push_back({0.5 * (m.points[half[i] >> 33] + m.points[half[i] >> 1 & 0xffffffffULL]), forward + back});
  }
  std::sort(out.defects.begin(), out.defects.end(), [](const auto& a, const auto& b) {
    return std::tie(a.at.x(), a.at.y(), a.at.z()) < std::tie(b.at.x(), b.at.y(), b.at.z());
  });
  // Step 1: closed and consistently oriented iff no edge is defective; then a CGAL mesh, built
  // face by face (a face that would make an edge or vertex non-manifold is refused).
  out.closed = out.defects.empty();
  Mesh mesh;
  out.manifold = out.closed && to_cgal(m, mesh);
  if (out.manifold) {
    std::vector<Mesh::Halfedge_index> pinched;
    PMP::non_manifold_vertices(mesh, std::back_inserter(pinched));
    out.manifold = pinched.empty();
  }
  if (!out.manifold) return out;
  // Step 2: the enclosed volume, by the divergence theorem.
  for (const auto& t : m.triangles) out.volume += m.points[t[0]].dot(m.points[t[1]].cross(m.points[t[2]])) / 6.0;
  // Step 3: self-intersections, by CGAL's box-intersection test over all faces or those the
  // pieces leave.
  out.self_intersection_test = test;
  if (test == SelfIntersectionTest::all_pairs) {
    out.triangles_tested_pairwise = m.triangles.size();
    out.self_intersecting = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
  } else if (test == SelfIntersectionTest::by_pieces) {
    const std::vector<Mesh::Face_index> left = faces_left_by_pieces(m, pieces);
    out.triangles_tested_pairwise = left.size();
    out.self_intersecting = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(left, mesh);
  }
  return out;
}

std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_triangles(const TriangleMesh& m) {
  Mesh mesh;
  if (!to_cgal(m, mesh)) throw std::invalid_argument("self_intersecting_triangles: the surface is not manifold");
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections<CGAL::Parallel_if_available_tag>(mesh, std::back_inserter(pairs));
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (const auto& [a, b] : pairs) out.emplace_back(static_cast<std::size_t>(a), static_cast<std::size_t>(b));
  std::sort(out.begin(), out.end());  // the parallel search reports in no fixed order
  return out;
}

std::string describe_defects(const SurfaceCheck& check, std::size_t count) {
  std::string where;
  for (std::size_t k = 0; k < std::min(count, check.defects.size()); ++k)
    where += fmt::format(" ({:.4g}, {:.4g}, {:.4g}) m used by {} triangles;", check.defects[k].at.x(),
                         check.defects[k].at.y(), check.defects[k].at.z(), check.defects[k].triangles);
  return where;
}

}  // namespace bedforge::meshing
