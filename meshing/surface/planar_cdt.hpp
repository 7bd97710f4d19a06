#pragma once
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <Eigen/Core>

#include <array>
#include <vector>

#include "meshing/surface/triangle_mesh.hpp"

namespace bedforge::meshing {

// What the flat meshers (the unrolled cylinder wall, plane faces) share: polygons in 2D
// coordinates of their face, and CGAL's constrained Delaunay triangulation of the sites.

using CdtKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<
    CdtKernel,
    CGAL::Triangulation_data_structure_2<CGAL::Triangulation_vertex_base_with_info_2<int, CdtKernel>,
                                         CGAL::Constrained_triangulation_face_base_2<CdtKernel>>,
    CGAL::Exact_predicates_tag>;

// Even-odd test of p against the closed polygon `poly`.
bool inside_polygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p);

// The closed polygon moved outward by `offset` along its vertex normals, resampled at `spacing`
// (starting half a step on when `stagger`).
std::vector<Eigen::Vector2d> offset_polygon(const std::vector<Eigen::Vector2d>& poly, double offset, double spacing,
                                            bool stagger);

// Polygons sorted by their lowest y, so a point is tested only against the few whose bounding
// boxes can hold it (holes are small against the face).
class PolygonIndex {
 public:
  explicit PolygonIndex(const std::vector<std::vector<Eigen::Vector2d>>& polygons);
  bool contains(const Eigen::Vector2d& q) const;  // inside any of them

 private:
  const std::vector<std::vector<Eigen::Vector2d>>& polygons_;
  std::vector<std::array<double, 4>> boxes_;  // x_min, x_max, y_min, y_max
  std::vector<std::size_t> by_y_;
  std::vector<double> y_low_;
  double tallest_ = 0.0;
};

// Inserts the sites into `cdt` row by row (rows of height `row`), back and forth, so each point
// is located from the previous one in a few steps; vertex info = site index. Returns the handles.
std::vector<Cdt::Vertex_handle> insert_in_rows(Cdt& cdt, const std::vector<Eigen::Vector2d>& sites, double row);

// Drops the vertices no triangle uses.
void drop_unused_points(TriangleMesh& m);

}  // namespace bedforge::meshing
