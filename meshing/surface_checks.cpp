#include "meshing/surface_checks.hpp"

#include <fmt/format.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <tuple>
#include <unordered_map>

namespace bedforge::meshing {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

nlohmann::json SurfaceCheck::to_json() const {
  return {{"manifold", manifold},
          {"closed", closed},
          {"self_intersections", self_intersections_checked ? nlohmann::json(self_intersecting) : nlohmann::json("not checked")},
          {"enclosed_volume_m3", volume},
          {"defective_edges", defects.size()}};
}

SurfaceCheck check_surface(const TriangleMesh& m, long self_intersection_limit) {
  SurfaceCheck out;
  std::vector<Kernel::Point_3> points;
  points.reserve(m.points.size());
  for (const auto& p : m.points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(m.triangles.size());
  for (const auto& t : m.triangles) polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
  // Step 0: every edge used once in each direction.
  std::unordered_map<long, std::pair<int, int>> uses;  // edge -> (triangles, sum of directions)
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const long a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
      auto& u = uses[std::min(a, b) << 32 | std::max(a, b)];
      ++u.first, u.second += a < b ? 1 : -1;
    }
  for (const auto& [key, u] : uses)
    if (u.first != 2 || u.second != 0) {
      const Eigen::Vector3d at = 0.5 * (m.points[key >> 32] + m.points[key & 0xffffffffL]);
      out.defects.push_back({at, u.first});
    }
  std::sort(out.defects.begin(), out.defects.end(), [](const auto& a, const auto& b) {
    return std::tie(a.at.x(), a.at.y(), a.at.z()) < std::tie(b.at.x(), b.at.y(), b.at.z());
  });
  // Step 1: closed and consistently oriented iff no edge is defective; then a CGAL mesh, built
  // face by face (a face that would make an edge or vertex non-manifold is refused).
  out.closed = out.defects.empty();
  Mesh mesh;
  mesh.reserve(m.points.size(), 3 * m.triangles.size() / 2, m.triangles.size());
  for (const auto& p : m.points) mesh.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z()));
  out.manifold = out.closed;
  for (const auto& t : m.triangles)
    if (out.manifold && mesh.add_face(Mesh::Vertex_index(t[0]), Mesh::Vertex_index(t[1]), Mesh::Vertex_index(t[2])) ==
                            Mesh::null_face())
      out.manifold = false;
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

std::string describe_defects(const SurfaceCheck& check, std::size_t count) {
  std::string where;
  for (std::size_t k = 0; k < std::min(count, check.defects.size()); ++k)
    where += fmt::format(" ({:.4g}, {:.4g}, {:.4g}) m used by {} triangles;", check.defects[k].at.x(),
                         check.defects[k].at.y(), check.defects[k].at.z(), check.defects[k].triangles);
  return where;
}

}  // namespace bedforge::meshing
