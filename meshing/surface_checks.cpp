#include "meshing/surface_checks.hpp"

#include <fmt/format.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <stdexcept>
#include <tuple>
#include <cstdint>

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

}  // namespace

nlohmann::json SurfaceCheck::to_json() const {
  return {{"manifold", manifold},
          {"closed", closed},
          {"self_intersections", self_intersections_checked ? nlohmann::json(self_intersecting) : nlohmann::json("not checked")},
          {"enclosed_volume_m3", volume},
          {"defective_edges", defects.size()}};
}

SurfaceCheck check_surface(const TriangleMesh& m, long self_intersection_limit) {
  SurfaceCheck out;
  // Step 0: every edge used once in each direction. Directed edges a -> b, sorted (a hash map
  // of 27 M edges at N = 1e4 took gigabytes and a malloc per edge).
  std::vector<std::uint64_t> half;
  half.reserve(3 * m.triangles.size());
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) half.push_back(std::uint64_t(t[k]) << 32 | std::uint32_t(t[(k + 1) % 3]));
  std::sort(half.begin(), half.end());
  auto uses = [&](std::uint64_t key) {
    const auto r = std::equal_range(half.begin(), half.end(), key);
    return static_cast<int>(r.second - r.first);
  };
  for (std::size_t i = 0, j = 0; i < half.size(); i = j) {
    while (j < half.size() && half[j] == half[i]) ++j;
    const std::uint64_t a = half[i] >> 32, b = half[i] & 0xffffffffULL;
    const int forward = static_cast<int>(j - i), back = uses(b << 32 | a);
    // Each undirected edge once: from its smaller end, or from its only direction.
    if ((forward != 1 || back != 1) && (a < b || back == 0))
      out.defects.push_back({0.5 * (m.points[a] + m.points[b]), forward + back});
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
  // Step 3: self-intersections, by CGAL's box-intersection test over all faces.
  if (static_cast<long>(m.triangles.size()) <= self_intersection_limit) {
    out.self_intersections_checked = true;
    out.self_intersecting = PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh);
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
