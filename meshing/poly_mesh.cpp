#include "meshing/poly_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace bedforge::meshing {

namespace {

using Tri = std::array<int, 3>;

Tri sorted(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

// The four faces of a positively oriented tet (a, b, c, d), each with its normal pointing out.
std::array<Tri, 4> outward_faces(const std::array<int, 4>& t) {
  return {{{t[0], t[2], t[1]}, {t[0], t[1], t[3]}, {t[0], t[3], t[2]}, {t[1], t[2], t[3]}}};
}

double signed_volume(const std::vector<Eigen::Vector3d>& p, const std::array<int, 4>& t) {
  return (p[t[1]] - p[t[0]]).dot((p[t[2]] - p[t[0]]).cross(p[t[3]] - p[t[0]])) / 6.0;
}

struct TriHash {
  std::size_t operator()(const Tri& t) const {
    return static_cast<std::size_t>(t[0]) * 0x9E3779B97F4A7C15ULL ^ static_cast<std::size_t>(t[1]) * 0xC2B2AE3D27D4EB4FULL ^
           static_cast<std::size_t>(t[2]);
  }
};

}  // namespace

PolyMesh poly_mesh_from_tets(std::vector<Eigen::Vector3d> points, std::vector<std::array<int, 4>> tets,
                             const std::vector<std::array<int, 3>>& boundary, const std::vector<int>& patch,
                             const std::vector<std::string>& names, const std::vector<std::string>& types) {
  // Cells bottom to top.
  std::vector<double> zc(tets.size());
  for (std::size_t c = 0; c < tets.size(); ++c)
    zc[c] = points[tets[c][0]].z() + points[tets[c][1]].z() + points[tets[c][2]].z() + points[tets[c][3]].z();
  std::vector<int> order(tets.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return zc[a] < zc[b]; });
  std::vector<std::array<int, 4>> cells(tets.size());
  for (std::size_t c = 0; c < order.size(); ++c) {
    cells[c] = tets[order[c]];
    if (signed_volume(points, cells[c]) < 0.0) std::swap(cells[c][2], cells[c][3]);
  }

  // Every cell face, keyed by its sorted vertices: a key met twice is an internal face.
  struct CellFace {
    Tri key, face;
    int cell;
  };
  std::vector<CellFace> all;
  all.reserve(4 * cells.size());
  for (int c = 0; c < static_cast<int>(cells.size()); ++c)
    for (const Tri& f : outward_faces(cells[c])) all.push_back({sorted(f), f, c});
  std::sort(all.begin(), all.end(), [](const CellFace& a, const CellFace& b) {
    return a.key != b.key ? a.key < b.key : a.cell < b.cell;
  });

  std::unordered_map<Tri, int, TriHash> patch_of;
  patch_of.reserve(boundary.size());
  for (std::size_t b = 0; b < boundary.size(); ++b) patch_of.emplace(sorted(boundary[b]), patch[b]);

  auto where = [&](const Tri& f) {
    const Eigen::Vector3d c = (points[f[0]] + points[f[1]] + points[f[2]]) / 3.0;
    return fmt::format("({:.6g}, {:.6g}, {:.6g}) m", c.x(), c.y(), c.z());
  };
  struct Internal {
    int owner, neighbour;
    Tri face;
  };
  struct Boundary {
    int patch, owner;
    Tri face;
  };
  std::vector<Internal> internal;
  std::vector<Boundary> bnd;
  internal.reserve(2 * cells.size());
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i + 1;
    while (j < all.size() && all[j].key == all[i].key) ++j;
    if (j - i > 2)
      throw std::runtime_error(fmt::format("volume mesh: a face at {} is shared by {} cells", where(all[i].face), j - i));
    if (j - i == 2) {
      internal.push_back({all[i].cell, all[i + 1].cell, all[i].face});  // sorted by cell: i is the owner
    } else {
      const auto it = patch_of.find(all[i].key);
      if (it == patch_of.end())
        throw std::runtime_error(
            fmt::format("volume mesh: a boundary face at {} belongs to no surface patch", where(all[i].face)));
      bnd.push_back({it->second, all[i].cell, all[i].face});
    }
    i = j;
  }
  std::sort(internal.begin(), internal.end(), [](const Internal& a, const Internal& b) {
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  std::stable_sort(bnd.begin(), bnd.end(), [](const Boundary& a, const Boundary& b) {
    return a.patch != b.patch ? a.patch < b.patch : a.owner < b.owner;
  });

  PolyMesh m;
  m.cells = static_cast<int>(cells.size());
  m.faces.reserve(internal.size() + bnd.size());
  for (const Internal& f : internal) {
    m.faces.push_back(f.face);
    m.owner.push_back(f.owner);
    m.neighbour.push_back(f.neighbour);
  }
  for (std::size_t p = 0; p < names.size(); ++p) m.patches.push_back({names[p], types[p], 0, 0});
  std::size_t k = 0;
  for (int p = 0; p < static_cast<int>(names.size()); ++p) {
    m.patches[p].start = static_cast<int>(m.faces.size());
    for (; k < bnd.size() && bnd[k].patch == p; ++k) {
      m.faces.push_back(bnd[k].face);
      m.owner.push_back(bnd[k].owner);
    }
    m.patches[p].size = static_cast<int>(m.faces.size()) - m.patches[p].start;
  }

  // Drop points no cell uses (gmsh keeps none, but a caller's surface may) and renumber.
  std::vector<int> used(points.size(), -1);
  int n = 0;
  for (auto& f : m.faces)
    for (int& v : f) {
      if (used[v] < 0) used[v] = n++;
      v = used[v];
    }
  m.points.resize(n);
  for (std::size_t v = 0; v < points.size(); ++v)
    if (used[v] >= 0) m.points[used[v]] = points[v];
  return m;
}

std::vector<std::array<int, 4>> cell_tets(const PolyMesh& m) {
  std::vector<std::array<int, 4>> cells(m.cells, {-1, -1, -1, -1});
  std::vector<int> filled(m.cells, 0);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int c : {m.owner[f], f < m.neighbour.size() ? m.neighbour[f] : -1}) {
      if (c < 0) continue;
      auto& cell = cells[c];
      for (int v : m.faces[f])
        if (std::find(cell.begin(), cell.begin() + filled[c], v) == cell.begin() + filled[c]) cell[filled[c]++] = v;
    }
  return cells;
}

std::vector<double> cell_volumes(const PolyMesh& m) {
  // Divergence theorem over each cell's faces: V = sum (x_f . S_f) / 3, sign by owner/neighbour.
  std::vector<double> vol(m.cells, 0.0);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto& t = m.faces[f];
    const Eigen::Vector3d& a = m.points[t[0]];
    const double v = a.dot((m.points[t[1]] - a).cross(m.points[t[2]] - a)) / 6.0;
    vol[m.owner[f]] += v;
    if (f < m.neighbour.size()) vol[m.neighbour[f]] -= v;
  }
  return vol;
}

std::vector<Eigen::Vector3d> cell_centres(const PolyMesh& m) {
  // A tet's centre is the mean of its four vertices; each vertex appears in three of its faces.
  std::vector<Eigen::Vector3d> c(m.cells, Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto& t = m.faces[f];
    const Eigen::Vector3d s = m.points[t[0]] + m.points[t[1]] + m.points[t[2]];
    c[m.owner[f]] += s;
    if (f < m.neighbour.size()) c[m.neighbour[f]] += s;
  }
  for (auto& x : c) x /= 12.0;
  return c;
}

}  // namespace bedforge::meshing
