#include "meshing/surface/triangle_mesh.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <tuple>

namespace bedforge::meshing {

int TriangleMesh::patch_index(const std::string& name) {
  const auto it = std::find(patches.begin(), patches.end(), name);
  if (it != patches.end()) return static_cast<int>(it - patches.begin());
  patches.push_back(name);
  return static_cast<int>(patches.size()) - 1;
}

void TriangleMesh::append(const TriangleMesh& other) {
  const int offset = static_cast<int>(points.size());
  points.insert(points.end(), other.points.begin(), other.points.end());
  std::vector<int> to;  // other's patch indices -> ours
  for (const auto& name : other.patches) to.push_back(patch_index(name));
  for (std::size_t t = 0; t < other.triangles.size(); ++t) {
    const auto& tri = other.triangles[t];
    triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
    patch.push_back(to[other.patch[t]]);
  }
}

void TriangleMesh::reserve(std::size_t more_points, std::size_t more_triangles) {
  points.reserve(points.size() + more_points);
  triangles.reserve(triangles.size() + more_triangles);
  patch.reserve(patch.size() + more_triangles);
}

void TriangleMesh::weld() {
  // Keyed by the coordinates' bits: only bit-identical points merge. An open-addressing table of
  // indices into `kept` (a node-based hash map of 1e7 points cost an allocation per point).
  using Bits = std::array<std::uint64_t, 3>;
  auto bits = [](const Eigen::Vector3d& p) {
    Bits b;
    for (int k = 0; k < 3; ++k) b[k] = std::bit_cast<std::uint64_t>(p[k] == 0.0 ? 0.0 : p[k]);  // -0 as +0
    return b;
  };
  const std::size_t mask = std::bit_ceil(2 * points.size() + 1) - 1;
  auto home = [mask](const Bits& b) {
    std::uint64_t h = b[0] * 0x9E3779B97F4A7C15ULL ^ b[1] * 0xC2B2AE3D27D4EB4FULL ^ b[2] * 0x165667B19E3779F9ULL;
    h ^= h >> 29;
    return static_cast<std::size_t>(h * 0xBF58476D1CE4E5B9ULL >> 17) & mask;
  };
  std::vector<int> slot(mask + 1, -1);
  std::vector<int> to(points.size());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Bits key = bits(points[i]);
    std::size_t h = home(key);
    while (slot[h] >= 0 && bits(kept[slot[h]]) != key) h = (h + 1) & mask;
    if (slot[h] < 0) {
      slot[h] = static_cast<int>(kept.size());
      kept.push_back(points[i]);
    }
    to[i] = slot[h];
  }
  points = std::move(kept);
  for (auto& t : triangles)
    for (int& v : t) v = to[v];
}

double enclosed_volume(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) v += m.points[t[0]].dot(m.points[t[1]].cross(m.points[t[2]])) / 6.0;
  return v;
}

void orient_by(TriangleMesh& m, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& desired) {
  for (auto& t : m.triangles) {
    const Eigen::Vector3d &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
    if ((b - a).cross(c - a).dot(desired((a + b + c) / 3.0)) < 0.0) std::swap(t[1], t[2]);
  }
}

double min_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const std::array<const Eigen::Vector3d*, 3> corner{&a, &b, &c};
  double smallest = 180.0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& at = *corner[k];
    const Eigen::Vector3d u = *corner[(k + 1) % 3] - at, v = *corner[(k + 2) % 3] - at;
    const double cosine = u.dot(v) / std::max(u.norm() * v.norm(), 1e-300);
    smallest = std::min(smallest, std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi);
  }
  return smallest;
}

double min_angle_deg(const TriangleMesh& m, std::size_t t) {
  const auto& tri = m.triangles[t];
  return min_angle_deg(m.points[tri[0]], m.points[tri[1]], m.points[tri[2]]);
}

TriangleMesh triangles_below_angle(const TriangleMesh& m, double limit_deg) {
  TriangleMesh out;
  out.patches = m.patches;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    if (min_angle_deg(m, t) >= limit_deg) continue;
    const int first = static_cast<int>(out.points.size());
    for (int v : m.triangles[t]) out.points.push_back(m.points[v]);
    out.triangles.push_back({first, first + 1, first + 2});
    out.patch.push_back(m.patch[t]);
  }
  return out;
}

MeshQuality mesh_quality(const TriangleMesh& m) {
  MeshQuality q;
  double min_edge = std::numeric_limits<double>::infinity(), max_edge = 0.0, min_angle = 180.0;
#pragma omp parallel for schedule(static) reduction(min : min_edge, min_angle) reduction(max : max_edge)
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const double l = (m.points[m.triangles[t][(k + 1) % 3]] - m.points[m.triangles[t][k]]).norm();
      min_edge = std::min(min_edge, l), max_edge = std::max(max_edge, l);
    }
    min_angle = std::min(min_angle, min_angle_deg(m, t));
  }
  q.min_edge = m.triangles.empty() ? 0.0 : min_edge;
  q.max_edge = max_edge;
  q.min_angle_deg = min_angle;
  return q;
}

}  // namespace bedforge::meshing
