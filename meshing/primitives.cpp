#include "meshing/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>

namespace bedforge::meshing {

namespace {

constexpr int kMaxLevel = 6;  // 81920 triangles per sphere

// Unit icospheres of levels 0..kMaxLevel, built once.
const std::vector<TriangleMesh>& unit_icospheres() {
  static const std::vector<TriangleMesh> levels = [] {
    std::vector<TriangleMesh> out;
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    TriangleMesh m;
    for (auto p : {Eigen::Vector3d(-1, t, 0), Eigen::Vector3d(1, t, 0), Eigen::Vector3d(-1, -t, 0), Eigen::Vector3d(1, -t, 0),
                   Eigen::Vector3d(0, -1, t), Eigen::Vector3d(0, 1, t), Eigen::Vector3d(0, -1, -t), Eigen::Vector3d(0, 1, -t),
                   Eigen::Vector3d(t, 0, -1), Eigen::Vector3d(t, 0, 1), Eigen::Vector3d(-t, 0, -1), Eigen::Vector3d(-t, 0, 1)})
      m.points.push_back(p.normalized());
    m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    out.push_back(m);
    for (int level = 1; level <= kMaxLevel; ++level) {
      TriangleMesh next;
      next.points = out.back().points;
      std::map<std::pair<int, int>, int> midpoint;
      auto mid = [&](int a, int b) {
        const auto key = std::minmax(a, b);
        const auto it = midpoint.find(key);
        if (it != midpoint.end()) return it->second;
        next.points.push_back((next.points[a] + next.points[b]).normalized());
        return midpoint[key] = static_cast<int>(next.points.size()) - 1;
      };
      for (const auto& tr : out.back().triangles) {
        const int ab = mid(tr[0], tr[1]), bc = mid(tr[1], tr[2]), ca = mid(tr[2], tr[0]);
        next.triangles.insert(next.triangles.end(), {{tr[0], ab, ca}, {tr[1], bc, ab}, {tr[2], ca, bc}, {ab, bc, ca}});
      }
      out.push_back(std::move(next));
    }
    return out;
  }();
  return levels;
}

int sphere_level(double r, double edge) {
  // Icosahedron edge 1.0515 r, halved at every level.
  int level = 0;
  while (level < kMaxLevel && 1.0515 * r / std::pow(2.0, level) > edge) ++level;
  return level;
}

// Flips every triangle whose normal disagrees with `desired(centroid)`.
void orient(TriangleMesh& m, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& desired) {
  for (auto& t : m.triangles) {
    const Eigen::Vector3d &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
    if ((b - a).cross(c - a).dot(desired((a + b + c) / 3.0)) < 0.0) std::swap(t[1], t[2]);
  }
}

Eigen::Vector3d on_circle(double R, int j, int n, bool stagger, double z) {
  const double theta = (j + (stagger ? 0.5 : 0.0)) * (2.0 * std::numbers::pi / n);
  return {R * std::cos(theta), R * std::sin(theta), z};
}

}  // namespace

TriangleMesh sphere_mesh(const Eigen::Vector3d& c, double r, double edge, bool outward, const std::string& patch) {
  TriangleMesh m = unit_icospheres()[sphere_level(r, edge)];
  for (auto& p : m.points) p = c + r * p;
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient(m, [&](const Eigen::Vector3d& q) { return outward ? Eigen::Vector3d(q - c) : Eigen::Vector3d(c - q); });
  return m;
}

double sphere_chordal_deviation(double r, double edge) {
  const TriangleMesh& m = unit_icospheres()[sphere_level(r, edge)];
  double worst = 0.0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d n = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]).normalized();
    worst = std::max(worst, 1.0 - std::abs(n.dot(m.points[t[0]])));
  }
  return r * worst;
}

int ring_points(double R, double edge) {
  return std::max(8, static_cast<int>(std::ceil(2.0 * std::numbers::pi * R / edge)));
}

bool top_ring_staggered(double z0, double z1, double edge) {
  const int nz = std::max(1, static_cast<int>(std::ceil((z1 - z0) / (edge * std::sqrt(3.0) / 2.0))));
  return nz % 2 == 1;
}

TriangleMesh tube_mesh(double R, double z0, double z1, double edge, bool outward, const std::string& patch) {
  TriangleMesh m;
  const int n = ring_points(R, edge);
  const int nz = std::max(1, static_cast<int>(std::ceil((z1 - z0) / (edge * std::sqrt(3.0) / 2.0))));
  for (int k = 0; k <= nz; ++k) {
    const double z = k == nz ? z1 : z0 + (z1 - z0) * k / nz;
    for (int j = 0; j < n; ++j) m.points.push_back(on_circle(R, j, n, k % 2 == 1, z));
  }
  auto at = [&](int k, int j) { return k * n + (j % n); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j) {
      if (k % 2 == 0) {  // ring k+1 is half a step ahead
        m.triangles.push_back({at(k, j), at(k, j + 1), at(k + 1, j)});
        m.triangles.push_back({at(k + 1, j), at(k, j + 1), at(k + 1, j + 1)});
      } else {  // ring k is half a step ahead
        m.triangles.push_back({at(k, j), at(k + 1, j + 1), at(k + 1, j)});
        m.triangles.push_back({at(k, j), at(k, j + 1), at(k + 1, j + 1)});
      }
    }
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient(m, [&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d radial(q.x(), q.y(), 0.0);
    return outward ? radial : Eigen::Vector3d(-radial);
  });
  return m;
}

TriangleMesh ring_mesh(double r_in, double r_out, double z, double edge, bool up, bool stagger_outer, bool stagger_inner,
                       const std::string& patch) {
  TriangleMesh m;
  const int rings = std::max(1, static_cast<int>(std::ceil((r_out - r_in) / (edge * std::sqrt(3.0) / 2.0))));
  // Ring m from the inside out; ring 0 of a disk is its centre.
  std::vector<int> first, count;
  std::vector<double> offset;
  for (int k = 0; k <= rings; ++k) {
    const double rho = k == rings ? r_out : r_in + (r_out - r_in) * k / rings;
    first.push_back(static_cast<int>(m.points.size()));
    if (rho <= 0.0) {
      m.points.emplace_back(0.0, 0.0, z);
      count.push_back(1);
      offset.push_back(0.0);
      continue;
    }
    const int n = k == 0 || k == rings ? ring_points(rho, edge) : std::max(6, ring_points(rho, edge));
    const bool stagger = (k == rings && stagger_outer) || (k == 0 && stagger_inner);
    for (int j = 0; j < n; ++j) m.points.push_back(on_circle(rho, j, n, stagger, z));
    count.push_back(n);
    offset.push_back(stagger ? 0.5 : 0.0);
  }
  for (int k = 0; k < rings; ++k) {
    const int na = count[k], nb = count[k + 1];
    auto A = [&](int i) { return first[k] + i % na; };
    auto B = [&](int j) { return first[k + 1] + j % nb; };
    if (na == 1) {  // fan around the centre
      for (int j = 0; j < nb; ++j) m.triangles.push_back({A(0), B(j), B(j + 1)});
      continue;
    }
    // Zip the two rings together, always advancing along the ring whose next vertex comes first.
    auto angle_a = [&](int i) { return (i + offset[k]) / na; };
    auto angle_b = [&](int j) { return (j + offset[k + 1]) / nb; };
    for (int i = 0, j = 0; i < na || j < nb;) {
      if (j >= nb || (i < na && angle_a(i + 1) <= angle_b(j + 1))) {
        m.triangles.push_back({A(i), A(i + 1), B(j)});
        ++i;
      } else {
        m.triangles.push_back({A(i), B(j + 1), B(j)});
        ++j;
      }
    }
  }
  m.patch.assign(m.triangles.size(), 0);
  m.patches = {patch};
  orient(m, [&](const Eigen::Vector3d&) { return Eigen::Vector3d(0, 0, up ? 1.0 : -1.0); });
  return m;
}

}  // namespace bedforge::meshing
