#include "meshing/surface/surface_checks.hpp"

#include <fmt/format.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace bedforge::meshing {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

namespace {

// Triangles `faces` of `m` (and the vertices they use) as a CGAL mesh, face k = triangle
// faces[k]; false when a triangle would make an edge or vertex non-manifold (CGAL refuses it,
// and the faces after it are not added).
bool to_cgal(const TriangleMesh& m, const std::vector<std::size_t>& faces, Mesh& mesh) {
  std::vector<int> vertex(m.points.size(), -1);
  std::size_t used = 0;
  for (std::size_t t : faces)
    for (int v : m.triangles[t])
      if (vertex[v] < 0) vertex[v] = static_cast<int>(used++);
  mesh.reserve(used, 3 * faces.size() / 2, faces.size());
  std::vector<int> point(used);
  for (std::size_t v = 0; v < vertex.size(); ++v)
    if (vertex[v] >= 0) point[vertex[v]] = static_cast<int>(v);
  for (int v : point) mesh.add_vertex(Kernel::Point_3(m.points[v].x(), m.points[v].y(), m.points[v].z()));
  for (std::size_t t : faces) {
    const auto& tri = m.triangles[t];
    if (mesh.add_face(Mesh::Vertex_index(vertex[tri[0]]), Mesh::Vertex_index(vertex[tri[1]]),
                      Mesh::Vertex_index(vertex[tri[2]])) == Mesh::null_face())
      return false;
  }
  return true;
}

// A box with the index of what it bounds (a face, or a unit of faces) as its id. CGAL sorts
// boxes in place and breaks ties of their lower corners by id: an id taken from the box's address
// (ID_FROM_BOX_ADDRESS) changes as the sort moves the box, which leaves the order inconsistent
// and let std::sort write out of bounds (the flat inlet's faces share their lower z).
struct IndexedBox : CGAL::Box_intersection_d::Box_d<double, 3, CGAL::Box_intersection_d::ID_NONE> {
  IndexedBox(const CGAL::Bbox_3& b, std::size_t index) : Box_d(b), index(index) {}
  std::size_t id() const { return index; }
  std::size_t index;
};

// The indices 0 .. n-1 of n triangles.
std::vector<std::size_t> all_of(std::size_t n) {
  std::vector<std::size_t> all(n);
  std::iota(all.begin(), all.end(), std::size_t{0});
  return all;
}

// Where a piece's triangles lie, as far as the argument uses it (lengths in m). A piece whose
// vertices stray from its shape by more than rounding is taken as Shape::other.
struct Region {
  SurfacePiece::Shape shape = SurfacePiece::Shape::other;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();  // plane: a point, the normal
  double radius = 0.0;  // sphere: of the ball that holds it; cylinder: of the solid cylinder inside it
  double half_width = 0.0;  // plane: of the slab that holds it
  std::vector<std::pair<Eigen::Vector3d, double>> cut_planes;  // sphere: n . (x - centre) <= h, h with its allowance
};

// The region of piece p of `m`. What rounding the vertices to the 12 significant digits of
// fluid.stl (round_to_ascii_stl) may move them is allowed for, far from the origin too.
Region region_of(const TriangleMesh& m, const SurfacePiece& p) {
  using Shape = SurfacePiece::Shape;
  Region r{p.shape, p.centre, p.axis, 0.0, 0.0, {}};
  if (p.first == p.last) return {};
  auto each_vertex = [&](const auto& f) {
    for (std::size_t t = p.first; t < p.last; ++t)
      for (int v : m.triangles[t]) f(m.points[v]);
  };
  double far = 0.0;  // from the centre
  each_vertex([&](const Eigen::Vector3d& v) { far = std::max(far, (v - p.centre).norm()); });
  const double rounding = 2e-11 * (p.centre.norm() + far);
  bool kept = true;
  if (p.shape == Shape::sphere) {
    r.radius = p.radius * (1.0 + 1e-9) + rounding;
    each_vertex([&](const Eigen::Vector3d& v) { kept = kept && (v - p.centre).norm() <= r.radius; });
    for (const auto& [normal, h] : p.cut_planes) {
      r.cut_planes.emplace_back(normal, h + (r.radius - p.radius) + 1e-12 * (p.centre.norm() + far));
      each_vertex([&](const Eigen::Vector3d& v) { kept = kept && normal.dot(v - p.centre) <= r.cut_planes.back().second; });
    }
  } else if (p.shape == Shape::cylinder) {
    // A triangle with its vertices within `slack` of the cylinder and edges up to L lies at least
    // sqrt((R - slack)^2 - (L / 2)^2) from the axis (the nearest point of a chord).
    const double slack = 1e-9 * p.radius + rounding;
    each_vertex([&](const Eigen::Vector3d& v) { kept = kept && std::abs(from_axis(v, p.centre, p.axis) - p.radius) <= slack; });
    double longest = 0.0;
    for (std::size_t t = p.first; t < p.last; ++t)
      for (int k = 0; k < 3; ++k) longest = std::max(longest, (m.points[m.triangles[t][(k + 1) % 3]] - m.points[m.triangles[t][k]]).norm());
    const double inner = p.radius - slack;
    kept = kept && longest < inner;
    r.radius = kept ? std::sqrt(inner * inner - 0.25 * longest * longest) - 1e-12 * (p.centre.norm() + far) : 0.0;
  } else if (p.shape == Shape::plane) {
    // The plane through the vertices' mean with the area-weighted normal; the slab as thick as
    // the vertices stray from it, which must be no more than rounding.
    Eigen::Vector3d normal = Eigen::Vector3d::Zero(), mean = Eigen::Vector3d::Zero();
    for (std::size_t t = p.first; t < p.last; ++t) {
      const auto& tri = m.triangles[t];
      normal += (m.points[tri[1]] - m.points[tri[0]]).cross(m.points[tri[2]] - m.points[tri[0]]);
      mean += m.points[tri[0]] + m.points[tri[1]] + m.points[tri[2]];
    }
    mean /= 3.0 * static_cast<double>(p.last - p.first);
    kept = normal.norm() > 0.0;
    r.centre = mean;
    r.axis = kept ? normal.normalized() : normal;
    double size = 0.0;
    each_vertex([&](const Eigen::Vector3d& v) {
      r.half_width = std::max(r.half_width, std::abs(r.axis.dot(v - mean)));
      size = std::max(size, (v - mean).norm());
    });
    kept = kept && r.half_width <= 1e-9 * size + 2e-11 * (mean.norm() + size);
    r.half_width += 1e-12 * (mean.norm() + size);
  }
  return kept ? r : Region{};
}

// Whether triangle (a, b, c) lies outside the region, so that it cannot meet the piece.
bool outside(const Region& r, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  using Shape = SurfacePiece::Shape;
  if (r.shape == Shape::sphere) {  // beyond a cut plane, or its box misses the ball
    for (const auto& [normal, h] : r.cut_planes)
      if (std::min({normal.dot(a - r.centre), normal.dot(b - r.centre), normal.dot(c - r.centre)}) > h) return true;
    double gap2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double lo = std::min({a[k], b[k], c[k]}), hi = std::max({a[k], b[k], c[k]});
      gap2 += std::pow(std::max({lo - r.centre[k], 0.0, r.centre[k] - hi}), 2);
    }
    return gap2 > r.radius * r.radius;
  }
  if (r.shape == Shape::plane) {  // wholly on one side of the slab
    const double sa = r.axis.dot(a - r.centre), sb = r.axis.dot(b - r.centre), sc = r.axis.dot(c - r.centre);
    return std::min({sa, sb, sc}) > r.half_width || std::max({sa, sb, sc}) < -r.half_width;
  }
  if (r.shape == Shape::cylinder) {  // inside the solid cylinder within the wall's facets (convex)
    return std::max({from_axis(a, r.centre, r.axis), from_axis(b, r.centre, r.axis), from_axis(c, r.centre, r.axis)}) < r.radius;
  }
  return false;
}

// The faces SelfIntersectionTest::by_pieces leaves to CGAL's test (the argument is in the
// header): every face of a piece of no known shape, and a face of the other pieces when it may
// meet a face of another piece, that is when their boxes meet and neither lies outside the
// other's region. Sweeping every face's box costs as much as CGAL's whole test, so the sweep is
// over units instead: each sphere piece whole (the box of its ball), the other pieces cut by a
// grid of cells about four of their edges wide. For each pair of units of two pieces whose boxes
// meet, A = the faces of one that meet the other's box and are not outside its region, B the
// same the other way; the faces of A and B whose boxes meet are left.
std::vector<std::size_t> faces_left_by_pieces(const TriangleMesh& m, const std::vector<SurfacePiece>& pieces) {
  using Shape = SurfacePiece::Shape;
  const std::size_t n = m.triangles.size();
  auto box_of = [&m](std::size_t t) {
    CGAL::Bbox_3 b;
    for (int v : m.triangles[t]) b += CGAL::Bbox_3(m.points[v].x(), m.points[v].y(), m.points[v].z(), m.points[v].x(),
                                                   m.points[v].y(), m.points[v].z());
    return b;
  };
  // Step 1: each piece's region, and the units: faces members[first, last) in `box`.
  struct Unit {
    std::size_t piece, first, last;
    CGAL::Bbox_3 box;
  };
  std::vector<Region> region(pieces.size());
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
    region[k] = region_of(m, p);
    if (region[k].shape == Shape::sphere) {
      const Region& r = region[k];
      units.push_back({k, members.size(), members.size() + (p.last - p.first),
                       CGAL::Bbox_3(r.centre.x() - r.radius, r.centre.y() - r.radius, r.centre.z() - r.radius,
                                    r.centre.x() + r.radius, r.centre.y() + r.radius, r.centre.z() + r.radius)});
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
  // Step 2: the pairs of units of two pieces, one at least of known shape, whose boxes meet (and
  // spheres whose balls meet), by a sweep of the units' boxes.
  std::vector<IndexedBox> boxes;
  boxes.reserve(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) boxes.emplace_back(units[u].box, u);
  std::vector<std::pair<std::size_t, std::size_t>> near;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const IndexedBox& a, const IndexedBox& b) {
    const Region &ru = region[units[a.index].piece], &rw = region[units[b.index].piece];
    if (units[a.index].piece == units[b.index].piece) return;  // a piece's own pairs: its shape, or tested whole
    if (ru.shape == Shape::other && rw.shape == Shape::other) return;  // both tested whole
    if (ru.shape == Shape::sphere && rw.shape == Shape::sphere && (ru.centre - rw.centre).norm() > ru.radius + rw.radius) return;
    const bool larger = units[a.index].last - units[a.index].first >= units[b.index].last - units[b.index].first;
    near.emplace_back(larger ? a.index : b.index, larger ? b.index : a.index);
  });
  // Grouped by their larger unit (a sphere's faces, with their boxes, are then gathered once for
  // all the units near it).
  std::sort(near.begin(), near.end());
  // Step 3: every face of a piece of no known shape, and the faces of the others that may meet a
  // face of another piece.
  std::vector<char> left(n, 0);
  for (const Unit& u : units)
    if (region[u.piece].shape == Shape::other)
      for (std::size_t i = u.first; i < u.last; ++i) left[members[i]] = 1;
  auto leave = [&left](std::size_t t) { std::atomic_ref<char>(left[t]).store(1, std::memory_order_relaxed); };
#pragma omp parallel
  {
    std::vector<IndexedBox> a_faces, b_faces, faces_of_u, faces_of_w;
    std::size_t u_gathered = units.size();
    // The faces of a unit with their boxes.
    auto gather = [&](const Unit& u, std::vector<IndexedBox>& out) {
      out.clear();
      for (std::size_t i = u.first; i < u.last; ++i) out.emplace_back(box_of(members[i]), members[i]);
    };
    // Of `faces`, those that meet w's box and are not outside w's region.
    auto may_meet = [&](const std::vector<IndexedBox>& faces, const Unit& w, std::vector<IndexedBox>& out) {
      out.clear();
      const Region& r = region[w.piece];
      for (const IndexedBox& b : faces) {
        const auto& tri = m.triangles[b.index];
        if (CGAL::do_overlap(b.bbox(), w.box) && !outside(r, m.points[tri[0]], m.points[tri[1]], m.points[tri[2]]))
          out.push_back(b);
      }
    };
#pragma omp for schedule(dynamic, 16)
    for (std::size_t k = 0; k < near.size(); ++k) {
      const Unit &u = units[near[k].first], &w = units[near[k].second];
      if (u_gathered != near[k].first) gather(u, faces_of_u), u_gathered = near[k].first;
      may_meet(faces_of_u, w, a_faces);
      if (a_faces.empty()) continue;
      gather(w, faces_of_w);
      may_meet(faces_of_w, u, b_faces);
      if (b_faces.empty()) continue;
      CGAL::box_intersection_d(a_faces.begin(), a_faces.end(), b_faces.begin(), b_faces.end(),
                               [&](const IndexedBox& x, const IndexedBox& y) { leave(x.index), leave(y.index); });
    }
  }
  std::vector<std::size_t> out;
  for (std::size_t t = 0; t < n; ++t)
    if (left[t]) out.push_back(t);
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
  // Step 0: the directed edges a -> b leaving each vertex a, with their triangles (about six a
  // vertex), so that every check below is a look-up in a short list.
  const std::size_t nv = m.points.size(), nt = m.triangles.size();
  if (nv > std::size_t{1} << 31 || nt > std::size_t{1} << 32) throw std::invalid_argument("check_surface: more than 2^31 vertices or 2^32 triangles");
  std::vector<std::size_t> first(nv + 1, 0);
  for (const auto& t : m.triangles)
    for (int v : t) ++first[v + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<std::pair<int, std::uint32_t>> leaving(3 * nt);  // (b, triangle) of each a -> b
  {
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) leaving[next[m.triangles[t][k]]++] = {m.triangles[t][(k + 1) % 3], static_cast<std::uint32_t>(t)};
  }
  auto uses = [&](int a, int b) {
    int n = 0;
    for (std::size_t k = first[a]; k < first[a + 1]; ++k) n += leaving[k].first == b;
    return n;
  };
  // Step 1: closed and consistently oriented iff every edge is used once in each direction. Each
  // defective edge is reported once: from its smaller end, or from its only direction.
  bool degenerate = false;  // a triangle with a repeated vertex
#pragma omp parallel for schedule(dynamic, 4096) reduction(|| : degenerate)
  for (std::size_t a = 0; a < nv; ++a)
    for (std::size_t k = first[a]; k < first[a + 1]; ++k) {
      const int b = leaving[k].first;
      const bool loop = b == static_cast<int>(a);
      degenerate = degenerate || loop;
      bool repeated = loop;  // or reported from its first use
      for (std::size_t j = first[a]; j < k; ++j) repeated = repeated || leaving[j].first == b;
      if (repeated) continue;
      const int forward = uses(static_cast<int>(a), b), back = uses(b, static_cast<int>(a));
      if ((forward != 1 || back != 1) && (static_cast<int>(a) < b || back == 0)) {
#pragma omp critical
        out.defects.push_back({0.5 * (m.points[a] + m.points[b]), forward + back});
      }
    }
  std::sort(out.defects.begin(), out.defects.end(), [](const auto& a, const auto& b) {
    return std::tie(a.at.x(), a.at.y(), a.at.z()) < std::tie(b.at.x(), b.at.y(), b.at.z());
  });
  out.closed = out.defects.empty();
  // Step 2: manifold iff, in addition, no triangle repeats a vertex and the triangles around each
  // vertex form one fan: stepping from a -> b in triangle (a, b, c) to a -> c visits every edge
  // leaving a before it comes back.
  bool pinched = false;
  if (out.closed && !degenerate) {
#pragma omp parallel for schedule(dynamic, 4096) reduction(|| : pinched)
    for (std::size_t a = 0; a < nv; ++a) {
      const std::size_t degree = first[a + 1] - first[a];
      if (degree == 0) continue;  // a vertex no triangle uses
      std::size_t k = first[a], steps = 0;
      do {
        const auto& t = m.triangles[leaving[k].second];
        const int i = t[0] == static_cast<int>(a) ? 0 : t[1] == static_cast<int>(a) ? 1 : 2, c = t[(i + 2) % 3];
        for (k = first[a]; leaving[k].first != c; ++k) {}
        ++steps;
      } while (k != first[a] && steps <= degree);
      pinched = pinched || steps != degree;
    }
  }
  out.manifold = out.closed && !degenerate && !pinched;
  if (!out.manifold) return out;
  // Step 3: the enclosed volume, by the divergence theorem.
  out.volume = enclosed_volume(m);
  // Step 4: self-intersections, by CGAL's box-intersection test on a CGAL mesh of the triangles
  // to test (all, or those the pieces leave): two of them that share an edge or a vertex in the
  // surface share it there too.
  out.self_intersection_test = test;
  if (test == SelfIntersectionTest::skip) return out;
  const std::vector<std::size_t> tested = test == SelfIntersectionTest::all_pairs ? all_of(nt) : faces_left_by_pieces(m, pieces);
  out.triangles_tested_pairwise = tested.size();
  Mesh mesh;
  if (to_cgal(m, tested, mesh)) {
    out.self_intersecting = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
    return out;
  }
  // CGAL links the fans around a vertex one face at a time and may refuse a subset's: then the
  // whole surface, with the faces to test as a range.
  std::vector<Mesh::Face_index> faces;
  for (std::size_t t : tested) faces.emplace_back(static_cast<Mesh::size_type>(t));
  mesh.clear();
  if (!to_cgal(m, all_of(nt), mesh)) throw std::logic_error("check_surface: CGAL refused a closed manifold surface");
  out.self_intersecting = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(faces, mesh);
  return out;
}

std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_triangles(const TriangleMesh& m) {
  Mesh mesh;
  if (!to_cgal(m, all_of(m.triangles.size()), mesh)) throw std::invalid_argument("self_intersecting_triangles: the surface is not manifold");
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
