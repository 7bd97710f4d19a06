#include "meshing/surface/delaunay_facets.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <unordered_map>
#include <utility>

namespace bedforge::meshing {

std::vector<std::size_t> off_delaunay_facets(const TriangleMesh& m, const std::vector<int>& points,
                                             const std::vector<std::size_t>& triangles) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Vb = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
  using Delaunay = CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vb>>;
  std::vector<std::pair<K::Point_3, int>> at;
  at.reserve(points.size());
  for (int v : points) at.emplace_back(K::Point_3(m.points[v].x(), m.points[v].y(), m.points[v].z()), v);
  const Delaunay dt(at.begin(), at.end());
  std::unordered_map<int, Delaunay::Vertex_handle> handle;
  for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) handle[v->info()] = v;
  std::vector<std::size_t> missing;
  Delaunay::Cell_handle c;
  int i, j, k;
  for (std::size_t t : triangles) {
    const auto& tri = m.triangles[t];
    if (!dt.is_facet(handle.at(tri[0]), handle.at(tri[1]), handle.at(tri[2]), c, i, j, k)) missing.push_back(t);
  }
  return missing;
}

}  // namespace bedforge::meshing
