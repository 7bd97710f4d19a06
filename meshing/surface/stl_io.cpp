#include "meshing/surface/stl_io.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace bedforge::meshing {

namespace {

constexpr int kDigits = 12;  // significant digits of a coordinate in an ASCII STL

Eigen::Vector3d unit_normal(const TriangleMesh& m, const std::array<int, 3>& t) {
  const Eigen::Vector3d n = (m.points[t[1]] - m.points[t[0]]).cross(m.points[t[2]] - m.points[t[0]]);
  const double len = n.norm();
  return len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
}

// Indices of the triangles of `patch` (all of them when negative), in order.
std::vector<std::size_t> triangles_of(const TriangleMesh& m, int patch) {
  std::vector<std::size_t> mine;
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    if (patch < 0 || m.patch[k] == patch) mine.push_back(k);
  return mine;
}

}  // namespace

double round_to_ascii_stl(double x) {
  char text[32];
  const char* end = fmt::format_to_n(text, sizeof text, "{:.{}g}", x, kDigits).out;
  std::from_chars(text, end, x);
  return x;
}

void round_to_ascii_stl(TriangleMesh& m) {
#pragma omp parallel for schedule(static)
  for (std::size_t v = 0; v < m.points.size(); ++v)
    for (int k = 0; k < 3; ++k) m.points[v][k] = round_to_ascii_stl(m.points[v][k]);
}

void write_stl_ascii_by_patch(std::ostream& out, const TriangleMesh& m) {
  constexpr std::size_t kChunk = 1 << 14, kBatch = 16;  // formatting is the slow part: chunks in parallel
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    out << "solid " << m.patches[p] << "\n";
    const std::vector<std::size_t> mine = triangles_of(m, static_cast<int>(p));
    for (std::size_t first = 0; first < mine.size(); first += kChunk * kBatch) {
      std::vector<fmt::memory_buffer> chunks(kBatch);  // fmt writes into its own buffer directly
#pragma omp parallel for schedule(dynamic)
      for (std::size_t c = 0; c < kBatch; ++c) {
        chunks[c].reserve(kChunk * 280);  // about 260 characters a facet
        auto it = std::back_inserter(chunks[c]);
        const std::size_t lo = first + c * kChunk, hi = std::min(mine.size(), lo + kChunk);
        for (std::size_t i = lo; i < hi; ++i) {
          const auto& t = m.triangles[mine[i]];
          const Eigen::Vector3d n = unit_normal(m, t);
          fmt::format_to(it, "  facet normal {:.9g} {:.9g} {:.9g}\n    outer loop\n", n.x(), n.y(), n.z());
          for (int v : t)
            fmt::format_to(it, "      vertex {:.{}g} {:.{}g} {:.{}g}\n", m.points[v].x(), kDigits, m.points[v].y(), kDigits,
                           m.points[v].z(), kDigits);
          fmt::format_to(it, "    endloop\n  endfacet\n");
        }
      }
      for (const auto& c : chunks) out.write(c.data(), static_cast<std::streamsize>(c.size()));
    }
    out << "endsolid " << m.patches[p] << "\n";
  }
}

void write_stl_binary(std::ostream& out, const TriangleMesh& m, int patch, const std::string& header) {
  std::string head(80, ' ');
  std::memcpy(head.data(), header.data(), std::min<std::size_t>(80, header.size()));
  out << head;
  const std::vector<std::size_t> mine = triangles_of(m, patch);
  const auto count = static_cast<std::uint32_t>(mine.size());
  out.write(reinterpret_cast<const char*>(&count), 4);  // little-endian on every Debian target we build for
  // Records of 50 bytes (normal, three corners as float32, attribute count 0), filled in
  // parallel a batch at a time and written in one call.
  constexpr std::size_t kRecord = 50, kBatch = 1 << 20;
  std::vector<char> buffer;
  for (std::size_t first = 0; first < mine.size(); first += kBatch) {
    const std::size_t last = std::min(mine.size(), first + kBatch);
    buffer.assign((last - first) * kRecord, 0);
#pragma omp parallel for schedule(static)
    for (std::size_t i = first; i < last; ++i) {
      const auto& t = m.triangles[mine[i]];
      const Eigen::Vector3d n = unit_normal(m, t);
      const Eigen::Vector3d* corners[3] = {&m.points[t[0]], &m.points[t[1]], &m.points[t[2]]};
      float record[12] = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) record[3 + 3 * c + k] = static_cast<float>((*corners[c])[k]);
      std::memcpy(buffer.data() + (i - first) * kRecord, record, sizeof record);
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  }
}

TriangleMesh read_stl_ascii_by_patch(const std::string& text, const std::string& source) {
  TriangleMesh m;
  int patch = -1, corner = 0;
  std::size_t line = 1;
  const char* p = text.data();
  const char* const end = p + text.size();
  auto fail = [&](const std::string& what) {
    throw InputError(fmt::format("{}:{}: {} (expected an ASCII STL as written by `bedforge surface`)", source, line, what));
  };
  auto skip_blanks = [&] {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
  };
  auto word = [&] {
    skip_blanks();
    const char* b = p;
    while (p < end && *p != ' ' && *p != '\t' && *p != '\n' && *p != '\r') ++p;
    return std::string_view(b, p - b);
  };
  while (p < end) {
    const std::string_view w = word();
    if (w == "solid") {
      patch = m.patch_index(std::string(word()));
    } else if (w == "vertex") {
      if (patch < 0) fail("a vertex outside any solid");
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k) {
        skip_blanks();
        const auto r = std::from_chars(p, end, v[k]);
        if (r.ec != std::errc()) fail("a vertex without three numbers");
        p = r.ptr;
      }
      m.points.push_back(v);
      if (++corner == 3) {
        const int n = static_cast<int>(m.points.size());
        m.triangles.push_back({n - 3, n - 2, n - 1});
        m.patch.push_back(patch);
        corner = 0;
      }
    } else if (w == "endloop" && corner != 0) {
      fail("a facet without three vertices");
    }
    while (p < end && *p != '\n') ++p;  // the rest of the line (normals, names) is not needed
    if (p < end) ++p, ++line;
  }
  if (m.triangles.empty()) fail("no triangles");
  m.weld();
  return m;
}

TriangleMesh read_stl_ascii_by_patch(const std::filesystem::path& file) {
  return read_stl_ascii_by_patch(read_file(file), file.string());
}

}  // namespace bedforge::meshing
