#include "meshing/stl_io.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <iterator>
#include <vector>

namespace bedforge::meshing {

namespace {

Eigen::Vector3d unit_normal(const TriangleMesh& m, const std::array<int, 3>& t) {
  const Eigen::Vector3d n = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]);
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

}  // namespace

std::string stl_ascii_by_patch(const TriangleMesh& m) {
  std::string out;
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    out += "solid " + m.patches[p] + "\n";
    std::vector<std::size_t> mine;
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      if (m.patch[k] == static_cast<int>(p)) mine.push_back(k);
    // Formatting is the slow part: chunks in parallel, joined in order.
    constexpr std::size_t kChunk = 1 << 15;
    std::vector<std::string> chunks((mine.size() + kChunk - 1) / kChunk);
#pragma omp parallel for schedule(dynamic)
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      auto it = std::back_inserter(chunks[c]);
      for (std::size_t i = c * kChunk; i < std::min(mine.size(), (c + 1) * kChunk); ++i) {
        const auto& t = m.triangles[mine[i]];
        const Eigen::Vector3d n = unit_normal(m, t);
        fmt::format_to(it, "  facet normal {:.9g} {:.9g} {:.9g}\n    outer loop\n", n.x(), n.y(), n.z());
        for (int v : t)
          fmt::format_to(it, "      vertex {:.12g} {:.12g} {:.12g}\n", m.points[v].x(), m.points[v].y(), m.points[v].z());
        fmt::format_to(it, "    endloop\n  endfacet\n");
      }
    }
    for (const auto& c : chunks) out += c;
    out += "endsolid " + m.patches[p] + "\n";
  }
  return out;
}

std::string stl_binary(const TriangleMesh& m, int patch, const std::string& header) {
  std::string out(80, ' ');
  std::memcpy(out.data(), header.data(), std::min<std::size_t>(80, header.size()));
  std::uint32_t count = 0;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) count += patch < 0 || m.patch[k] == patch;
  out.append(reinterpret_cast<const char*>(&count), 4);  // little-endian on every Debian target we build for
  auto put = [&](const Eigen::Vector3d& v) {
    const float f[3] = {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
    out.append(reinterpret_cast<const char*>(f), sizeof f);
  };
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    if (patch >= 0 && m.patch[k] != patch) continue;
    const auto& t = m.triangles[k];
    put(unit_normal(m, t));
    for (int v : t) put(m.points[v]);
    out.append(2, '\0');  // attribute byte count
  }
  return out;
}

}  // namespace bedforge::meshing
