#include "meshing/surface_checks.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

namespace bedforge::meshing {

namespace PMP = CGAL::Polygon_mesh_processing;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;

nlohmann::json SurfaceCheck::to_json() const {
  return {{"manifold", manifold},
          {"closed", closed},
          {"self_intersections", self_intersections_checked ? nlohmann::json(self_intersecting) : nlohmann::json("not checked")},
          {"enclosed_volume_m3", volume}};
}

SurfaceCheck check_surface(const TriangleMesh& m, long self_intersection_limit) {
  SurfaceCheck out;
  std::vector<Kernel::Point_3> points;
  points.reserve(m.points.size());
  for (const auto& p : m.points) points.emplace_back(p.x(), p.y(), p.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(m.triangles.size());
  for (const auto& t : m.triangles) polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
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
