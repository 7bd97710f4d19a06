#include "meshing/surface_checks.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
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
  // Step 1: the soup must describe an oriented 2-manifold to become a polygon mesh at all.
  out.manifold = PMP::is_polygon_soup_a_polygon_mesh(polygons);
  if (!out.manifold) return out;
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  // Step 2: closed (no border edges), then the enclosed volume.
  out.closed = CGAL::is_closed(mesh);
  if (out.closed) out.volume = PMP::volume(mesh);
  // Step 3: self-intersections, by CGAL's box-intersection test over all faces.
  if (static_cast<long>(m.triangles.size()) <= self_intersection_limit) {
    out.self_intersections_checked = true;
    out.self_intersecting = PMP::does_self_intersect(mesh);
  }
  return out;
}

}  // namespace bedforge::meshing
