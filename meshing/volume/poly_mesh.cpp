#include "meshing/volume/poly_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <climits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace bedforge::meshing {

std::string patch_type(const std::string& name) { return name == "inlet" || name == "outlet" ? "patch" : "wall"; }

Face::Face(std::initializer_list<int> points) : n(static_cast<int>(points.size())) {
  if (n < 3 || n > 4) throw std::invalid_argument("a face has 3 or 4 points");
  std::copy(points.begin(), points.end(), v.begin());
}

namespace {

// A face's points sorted, the key under which the two cells sharing it meet.
using Key = std::array<int, 4>;
Key key_of(const Face& f) {
  Key k{INT_MAX, INT_MAX, INT_MAX, INT_MAX};
  std::copy(f.begin(), f.end(), k.begin());
  std::sort(k.begin(), k.end());
  return k;
}

struct KeyHash {
  std::size_t operator()(const Key& k) const {
    std::size_t h = 0;
    for (int v : k) h = h * 0x9E3779B97F4A7C15ULL ^ static_cast<std::size_t>(v);
    return h;
  }
};

// The faces of a cell in gmsh's node order, in no particular orientation.
struct CellFaces {
  std::array<Face, 5> face;
  int n = 0;
};
CellFaces faces_of(const VolumeCell& c) {
  const auto& v = c.v;
  switch (c.n) {
    case 4:
      return {{Face{v[0], v[2], v[1]}, Face{v[0], v[1], v[3]}, Face{v[0], v[3], v[2]}, Face{v[1], v[2], v[3]}}, 4};
    case 5:
      return {{Face{v[0], v[3], v[2], v[1]}, Face{v[0], v[1], v[4]}, Face{v[1], v[2], v[4]}, Face{v[2], v[3], v[4]},
               Face{v[3], v[0], v[4]}},
              5};
    case 6:
      return {{Face{v[0], v[2], v[1]}, Face{v[3], v[4], v[5]}, Face{v[0], v[1], v[4], v[3]}, Face{v[1], v[2], v[5], v[4]},
               Face{v[2], v[0], v[3], v[5]}},
              5};
    default:
      throw std::invalid_argument(fmt::format("a cell of {} points is no tetrahedron, pyramid or prism", c.n));
  }
}

Eigen::Vector3d vertex_mean(const std::vector<Eigen::Vector3d>& p, const int* first, int n) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) s += p[first[k]];
  return s / n;
}

}  // namespace

FaceGeometry face_geometry(const std::vector<Eigen::Vector3d>& p, std::span<const int> f) {
  if (f.size() == 3)
    return {(p[f[0]] + p[f[1]] + p[f[2]]) / 3.0, 0.5 * (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]])};
  const Eigen::Vector3d mean = vertex_mean(p, f.data(), static_cast<int>(f.size()));
  Eigen::Vector3d sum_n = Eigen::Vector3d::Zero(), sum_ac = Eigen::Vector3d::Zero();
  double sum_a = 0.0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const Eigen::Vector3d& a = p[f[k]];
    const Eigen::Vector3d& b = p[f[(k + 1) % f.size()]];
    const Eigen::Vector3d n = (b - a).cross(mean - a);
    const double area = n.norm();
    sum_n += n;
    sum_a += area;
    sum_ac += area * (a + b + mean);
  }
  if (sum_a < 1e-150) return {mean, Eigen::Vector3d::Zero()};
  return {sum_ac / (3.0 * sum_a), 0.5 * sum_n};
}

namespace {

template <class Mesh>
CellGeometry cell_geometry_of(const Mesh& m) {
  // Face geometry is computed twice rather than kept: at 2 faces per cell it would be the
  // largest array of the mesh stage.
  std::vector<Eigen::Vector3d> estimate(m.cells, Eigen::Vector3d::Zero());
  std::vector<int> count(m.cells, 0);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Eigen::Vector3d c = face_geometry(m.points, m.faces[f]).centre;
    estimate[m.owner[f]] += c, ++count[m.owner[f]];
    if (f < m.neighbour.size()) estimate[m.neighbour[f]] += c, ++count[m.neighbour[f]];
  }
  for (int c = 0; c < m.cells; ++c) estimate[c] /= std::max(1, count[c]);
  count = {};
  CellGeometry g{std::vector<Eigen::Vector3d>(m.cells, Eigen::Vector3d::Zero()), std::vector<double>(m.cells, 0.0)};
  auto add = [&](int c, const FaceGeometry& face, double sign) {
    const double pyramid3 = sign * face.area.dot(face.centre - estimate[c]);  // 3 x the pyramid's volume
    g.centres[c] += pyramid3 * (0.75 * face.centre + 0.25 * estimate[c]);
    g.volumes[c] += pyramid3;
  };
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const FaceGeometry face = face_geometry(m.points, m.faces[f]);
    add(m.owner[f], face, 1.0);
    if (f < m.neighbour.size()) add(m.neighbour[f], face, -1.0);
  }
  for (int c = 0; c < m.cells; ++c) {
    g.centres[c] = std::abs(g.volumes[c]) > 1e-300 ? Eigen::Vector3d(g.centres[c] / g.volumes[c]) : estimate[c];
    g.volumes[c] /= 3.0;
  }
  return g;
}

}  // namespace

CellGeometry cell_geometry(const PolyMesh& m) { return cell_geometry_of(m); }
CellGeometry cell_geometry(const PolyhedralMesh& m) { return cell_geometry_of(m); }

std::vector<Eigen::Vector3d> cell_centres(const PolyMesh& m) { return cell_geometry(m).centres; }
std::vector<double> cell_volumes(const PolyMesh& m) { return cell_geometry(m).volumes; }

std::vector<VolumeCell> tetrahedra(const PolyMesh& m) {
  std::vector<VolumeCell> cells(m.cells);
  auto add_point = [&](int c, int v) {
    VolumeCell& cell = cells[c];
    if (cell.n < 4 && std::find(cell.v.begin(), cell.v.begin() + cell.n, v) == cell.v.begin() + cell.n) cell.v[cell.n++] = v;
  };
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int v : m.faces[f]) {
      add_point(m.owner[f], v);
      if (f < m.neighbour.size()) add_point(m.neighbour[f], v);
    }
  return cells;
}

PolyMesh poly_mesh_from_cells(std::vector<Eigen::Vector3d> points, const std::vector<VolumeCell>& input,
                              const std::vector<Face>& boundary, const std::vector<int>& patch,
                              const std::vector<std::string>& names, const std::vector<std::string>& types,
                              std::vector<int>* point_map) {
  // Cells bottom to top.
  std::vector<int> order(input.size());
  {
    std::vector<double> zc(input.size());
    for (std::size_t c = 0; c < input.size(); ++c) zc[c] = vertex_mean(points, input[c].v.data(), input[c].n).z();
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return zc[a] < zc[b]; });
  }
  // Face `local` of (sorted) cell c, turned to point out of it.
  auto cell_face = [&](int c, int local) {
    const VolumeCell& cell = input[order[c]];
    Face f = faces_of(cell).face[local];
    const Eigen::Vector3d& a = points[f[0]];
    // A quad's normal from its two diagonals, robust when it is warped.
    const Eigen::Vector3d n = f.size() == 4 ? (points[f[2]] - a).cross(points[f[3]] - points[f[1]])
                                            : (points[f[1]] - a).cross(points[f[2]] - a);
    if (n.dot(vertex_mean(points, f.begin(), f.size()) - vertex_mean(points, cell.v.data(), cell.n)) < 0.0)
      std::reverse(f.begin(), f.end());
    return f;
  };
  auto where = [&](const Face& f) {
    const Eigen::Vector3d c = vertex_mean(points, f.begin(), f.size());
    return fmt::format("({:.6g}, {:.6g}, {:.6g}) m", c.x(), c.y(), c.z());
  };

  // Every cell face by its sorted points and its place in its cell (not the face itself, which
  // at 4 faces per cell would be the stage's largest array): a key met twice is an internal face.
  struct CellFace {
    Key key;
    int cell, local;
  };
  struct Internal {
    int owner, neighbour, local;  // local: the face's place in its owner
  };
  struct Boundary {
    int patch, owner, local;
  };
  std::vector<Internal> internal;
  std::vector<Boundary> bnd;
  {
    std::vector<CellFace> all;
    all.reserve(4 * input.size());
    for (int c = 0; c < static_cast<int>(order.size()); ++c) {
      const CellFaces faces = faces_of(input[order[c]]);
      for (int k = 0; k < faces.n; ++k) all.push_back({key_of(faces.face[k]), c, k});
    }
    std::sort(all.begin(), all.end(), [](const CellFace& a, const CellFace& b) {
      return a.key != b.key ? a.key < b.key : a.cell < b.cell;
    });
    std::unordered_map<Key, int, KeyHash> patch_of;
    patch_of.reserve(boundary.size());
    for (std::size_t b = 0; b < boundary.size(); ++b) patch_of.emplace(key_of(boundary[b]), patch[b]);
    internal.reserve(2 * input.size());
    for (std::size_t i = 0; i < all.size();) {
      std::size_t j = i + 1;
      while (j < all.size() && all[j].key == all[i].key) ++j;
      if (j - i > 2)
        throw std::runtime_error(fmt::format("volume mesh: a face at {} is shared by {} cells",
                                             where(cell_face(all[i].cell, all[i].local)), j - i));
      if (j - i == 2) {
        internal.push_back({all[i].cell, all[i + 1].cell, all[i].local});  // sorted by cell: i is the owner
      } else {
        const auto it = patch_of.find(all[i].key);
        if (it == patch_of.end())
          throw std::runtime_error(fmt::format("volume mesh: a boundary face at {} belongs to no surface patch",
                                               where(cell_face(all[i].cell, all[i].local))));
        bnd.push_back({it->second, all[i].cell, all[i].local});
      }
      i = j;
    }
  }
  std::sort(internal.begin(), internal.end(), [](const Internal& a, const Internal& b) {
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  std::stable_sort(bnd.begin(), bnd.end(), [](const Boundary& a, const Boundary& b) {
    return a.patch != b.patch ? a.patch < b.patch : a.owner < b.owner;
  });

  PolyMesh m;
  m.cells = static_cast<int>(input.size());
  m.faces.reserve(internal.size() + bnd.size());
  m.owner.reserve(internal.size() + bnd.size());
  m.neighbour.reserve(internal.size());
  for (const Internal& f : internal) {
    m.faces.push_back(cell_face(f.owner, f.local));
    m.owner.push_back(f.owner);
    m.neighbour.push_back(f.neighbour);
  }
  internal = {};
  for (std::size_t p = 0; p < names.size(); ++p) m.patches.push_back({names[p], types[p], 0, 0, {}, Eigen::Vector3d::Zero()});
  std::size_t k = 0;
  for (int p = 0; p < static_cast<int>(names.size()); ++p) {
    m.patches[p].start = static_cast<int>(m.faces.size());
    for (; k < bnd.size() && bnd[k].patch == p; ++k) {
      m.faces.push_back(cell_face(bnd[k].owner, bnd[k].local));
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
  if (point_map) *point_map = std::move(used);
  return m;
}

bool has_prisms(const PolyMesh& mesh) {
  std::vector<std::array<int, 2>> sides(mesh.cells);  // per cell: triangles, quadrilaterals
  auto count = [&](int cell, int n) {
    if (n == 3) ++sides[cell][0];
    if (n == 4) ++sides[cell][1];
  };
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    count(mesh.owner[f], mesh.faces[f].size());
    if (f < mesh.neighbour.size()) count(mesh.neighbour[f], mesh.faces[f].size());
  }
  return std::any_of(sides.begin(), sides.end(), [](const std::array<int, 2>& s) { return s[0] == 2 && s[1] == 3; });
}

}  // namespace bedforge::meshing
