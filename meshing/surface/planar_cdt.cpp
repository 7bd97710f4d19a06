#include "meshing/surface/planar_cdt.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "meshing/surface/spaced_points.hpp"

namespace bedforge::meshing {

bool inside_polygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i].y() > p.y()) != (poly[j].y() > p.y()) &&
        p.x() < (poly[j].x() - poly[i].x()) * (p.y() - poly[i].y()) / (poly[j].y() - poly[i].y()) + poly[i].x())
      in = !in;
  return in;
}

std::vector<Eigen::Vector2d> offset_polygon(const std::vector<Eigen::Vector2d>& poly, double offset, double spacing,
                                            bool stagger) {
  const std::size_t n = poly.size();
  double area = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto &a = poly[i], &b = poly[(i + 1) % n];
    area += a.x() * b.y() - b.x() * a.y();
  }
  const double sense = area > 0.0 ? 1.0 : -1.0;  // outward normal of edge (dx, dy) is sense * (dy, -dx)
  std::vector<Eigen::Vector2d> moved;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e0 = (poly[i] - poly[(i + n - 1) % n]).normalized(), e1 = (poly[(i + 1) % n] - poly[i]).normalized();
    const Eigen::Vector2d normal = sense * Eigen::Vector2d(e0.y() + e1.y(), -e0.x() - e1.x()).normalized();
    moved.push_back(poly[i] + offset * normal);
  }
  return resample_loop(moved, spacing, stagger);
}

PolygonIndex::PolygonIndex(const std::vector<std::vector<Eigen::Vector2d>>& polygons) : polygons_(polygons) {
  for (const auto& poly : polygons) {
    std::array<double, 4> box{poly[0].x(), poly[0].x(), poly[0].y(), poly[0].y()};
    for (const auto& q : poly)
      box = {std::min(box[0], q.x()), std::max(box[1], q.x()), std::min(box[2], q.y()), std::max(box[3], q.y())};
    boxes_.push_back(box);
    tallest_ = std::max(tallest_, box[3] - box[2]);
  }
  by_y_.resize(polygons.size());
  std::iota(by_y_.begin(), by_y_.end(), 0);
  std::sort(by_y_.begin(), by_y_.end(), [&](std::size_t a, std::size_t b) { return boxes_[a][2] < boxes_[b][2]; });
  for (std::size_t h : by_y_) y_low_.push_back(boxes_[h][2]);
}

bool PolygonIndex::contains(const Eigen::Vector2d& q) const {
  const auto first = std::lower_bound(y_low_.begin(), y_low_.end(), q.y() - tallest_) - y_low_.begin();
  for (auto k = first; k < static_cast<long>(y_low_.size()) && y_low_[k] <= q.y(); ++k) {
    const std::size_t h = by_y_[k];
    const auto& b = boxes_[h];
    if (q.x() >= b[0] && q.x() <= b[1] && q.y() <= b[3] && inside_polygon(polygons_[h], q)) return true;
  }
  return false;
}

std::vector<Cdt::Vertex_handle> insert_in_rows(Cdt& cdt, const std::vector<Eigen::Vector2d>& sites, double row) {
  std::vector<std::size_t> order(sites.size());
  std::iota(order.begin(), order.end(), 0);
  double y0 = sites.empty() ? 0.0 : sites[0].y();
  for (const auto& q : sites) y0 = std::min(y0, q.y());
  auto row_of = [&](std::size_t i) { return static_cast<long>(std::floor((sites[i].y() - y0) / row)); };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const long ra = row_of(a), rb = row_of(b);
    if (ra != rb) return ra < rb;
    return ra % 2 == 0 ? sites[a].x() < sites[b].x() : sites[a].x() > sites[b].x();
  });
  std::vector<Cdt::Vertex_handle> handle(sites.size());
  Cdt::Face_handle hint;
  for (std::size_t i : order) {
    handle[i] = cdt.insert(CdtKernel::Point_2(sites[i].x(), sites[i].y()), hint);
    handle[i]->info() = static_cast<int>(i);
    hint = handle[i]->face();
  }
  return handle;
}

void drop_unused_points(TriangleMesh& m) {
  std::vector<int> to(m.points.size(), -1);
  std::vector<Eigen::Vector3d> kept;
  for (auto& t : m.triangles)
    for (int& v : t) {
      if (to[v] < 0) to[v] = static_cast<int>(kept.size()), kept.push_back(m.points[v]);
      v = to[v];
    }
  m.points = std::move(kept);
}

}  // namespace bedforge::meshing
