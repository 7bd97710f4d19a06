#pragma once
// Surface triangles that are no face of the Delaunay tetrahedralisation of the surface's points.
// gmsh's tetrahedra start from that tetrahedralisation and recover each such face over the
// whole mesh, at several times the memory and time of the tetrahedra (docs/findings.md).
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <limits>
#include <utility>
#include <vector>

#include "meshing/surface/triangle_mesh.hpp"

namespace test_support {

// Of triangles [first, last) of m (all by default), how many gmsh would have to recover.
inline long triangles_gmsh_must_recover(const bedforge::meshing::TriangleMesh& m, std::size_t first = 0,
                                        std::size_t last = std::numeric_limits<std::size_t>::max()) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Dt = CGAL::Delaunay_triangulation_3<
      K, CGAL::Triangulation_data_structure_3<CGAL::Triangulation_vertex_base_with_info_3<int, K>>>;
  std::vector<std::pair<K::Point_3, int>> points;
  for (std::size_t k = 0; k < m.points.size(); ++k)
    points.emplace_back(K::Point_3(m.points[k].x(), m.points[k].y(), m.points[k].z()), static_cast<int>(k));
  const Dt dt(points.begin(), points.end());
  std::vector<Dt::Vertex_handle> handle(m.points.size());
  for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) handle[v->info()] = v;
  long missing = 0;
  Dt::Cell_handle c;
  int i, j, k;
  for (std::size_t t = first; t < std::min(last, m.triangles.size()); ++t)
    missing += !dt.is_facet(handle[m.triangles[t][0]], handle[m.triangles[t][1]], handle[m.triangles[t][2]], c, i, j, k);
  return missing;
}

}  // namespace test_support
