#include "meshing/volume/flat_ears.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bedforge::meshing {

namespace {

// Where `cell` is in `sorted` (cells in increasing order), or -1.
int position(const std::vector<int>& sorted, int cell) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), cell);
  return it != sorted.end() && *it == cell ? static_cast<int>(it - sorted.begin()) : -1;
}

}  // namespace

std::vector<int> flat_ears(const PolyMesh& m, double max_turn_deg) {
  // Every boundary face by its cell; the points on patches other than walls.
  struct Owned {
    int cell, face, patch;
  };
  std::vector<Owned> boundary;
  std::vector<char> fixed(m.points.size(), 0);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k) {
    const auto& p = m.patches[k];
    for (int f = p.start; f < p.start + p.size; ++f) {
      boundary.push_back({m.owner[f], f, k});
      if (p.type != "wall")
        for (int v : m.faces[f]) fixed[v] = 1;
    }
  }
  std::sort(boundary.begin(), boundary.end(), [](const Owned& a, const Owned& b) { return a.cell < b.cell; });
  // Cells with exactly two boundary faces, triangles on one wall patch, turning by less than the limit.
  const double min_cos = std::cos(max_turn_deg * std::numbers::pi / 180.0);
  std::vector<int> candidates;
  for (std::size_t i = 0; i < boundary.size();) {
    std::size_t j = i;
    while (j < boundary.size() && boundary[j].cell == boundary[i].cell) ++j;
    if (j - i == 2) {
      const Owned &a = boundary[i], &b = boundary[i + 1];
      const auto& patch = m.patches[a.patch];
      if (a.patch == b.patch && patch.type == "wall" && m.faces[a.face].size() == 3 && m.faces[b.face].size() == 3) {
        const Eigen::Vector3d na = face_geometry(m.points, m.faces[a.face]).area,
                              nb = face_geometry(m.points, m.faces[b.face]).area;
        const bool free = std::none_of(m.faces[a.face].begin(), m.faces[a.face].end(), [&](int v) { return fixed[v]; }) &&
                          std::none_of(m.faces[b.face].begin(), m.faces[b.face].end(), [&](int v) { return fixed[v]; });
        if (free && na.dot(nb) > min_cos * na.norm() * nb.norm()) candidates.push_back(a.cell);
      }
    }
    i = j;
  }
  // A tetrahedron: besides its two boundary triangles, exactly two internal triangles.
  std::vector<int> internal(candidates.size(), 0);
  std::vector<char> neighbour_ear(candidates.size(), 0), not_triangle(candidates.size(), 0);
  for (int f = 0; f < m.internal_faces(); ++f) {
    const int o = position(candidates, m.owner[f]), n = position(candidates, m.neighbour[f]);
    for (int k : {o, n})
      if (k >= 0) ++internal[k], not_triangle[k] |= m.faces[f].size() != 3;
    if (o >= 0 && n >= 0) neighbour_ear[n] = 1;  // the owner, numbered first, is kept
  }
  std::vector<int> ears;
  for (std::size_t k = 0; k < candidates.size(); ++k)
    if (internal[k] == 2 && !not_triangle[k] && !neighbour_ear[k]) ears.push_back(candidates[k]);
  return ears;
}

double cut_ears(PolyMesh& m, const std::vector<int>& ears) {
  if (ears.empty()) return 0.0;
  // A kept cell's number less the ears before it.
  auto renumbered = [&](int cell) {
    return cell - static_cast<int>(std::lower_bound(ears.begin(), ears.end(), cell) - ears.begin());
  };
  // Each ear's wall patch, from its wall faces.
  std::vector<int> ear_patch(ears.size(), -1);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k)
    for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f)
      if (const int e = position(ears, m.owner[f]); e >= 0) ear_patch[e] = k;
  // The internal faces: kept (renumbered, their order unchanged) or moved to the ear's wall.
  std::vector<Face> faces;
  std::vector<int> owner, neighbour;
  std::vector<std::vector<std::pair<Face, int>>> joining(m.patches.size());  // face, its new owner
  std::vector<std::vector<int>> ear_points(ears.size());
  for (int f = 0; f < m.internal_faces(); ++f) {
    const int o = m.owner[f], n = m.neighbour[f];
    const int eo = position(ears, o), en = position(ears, n);
    if (eo >= 0 || en >= 0) {
      const bool ear_owns = eo >= 0;
      const int e = ear_owns ? eo : en, other = ear_owns ? n : o;
      Face face = m.faces[f];
      if (ear_owns) std::reverse(face.begin(), face.end());  // it pointed into `other`
      joining[ear_patch[e]].push_back({face, renumbered(other)});
      for (int v : face)
        if (std::find(ear_points[e].begin(), ear_points[e].end(), v) == ear_points[e].end()) ear_points[e].push_back(v);
      continue;
    }
    faces.push_back(m.faces[f]);
    owner.push_back(renumbered(o));
    neighbour.push_back(renumbered(n));
  }
  double volume = 0.0;
  for (const auto& p : ear_points) {
    const Eigen::Vector3d &a = m.points[p[0]], &b = m.points[p[1]], &c = m.points[p[2]], &d = m.points[p[3]];
    volume += std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
  }
  // The boundary faces patch by patch: the ears' wall faces go, their other faces join.
  std::vector<PolyMesh::Patch> patches = m.patches;
  for (std::size_t k = 0; k < m.patches.size(); ++k) {
    patches[k].start = static_cast<int>(faces.size());
    const auto& p = m.patches[k];
    for (int f = p.start; f < p.start + p.size; ++f)
      if (position(ears, m.owner[f]) < 0) faces.push_back(m.faces[f]), owner.push_back(renumbered(m.owner[f]));
    for (const auto& [face, cell] : joining[k]) faces.push_back(face), owner.push_back(cell);
    patches[k].size = static_cast<int>(faces.size()) - patches[k].start;
  }
  m.faces = std::move(faces);
  m.owner = std::move(owner);
  m.neighbour = std::move(neighbour);
  m.patches = std::move(patches);
  m.cells -= static_cast<int>(ears.size());
  return volume;
}

}  // namespace bedforge::meshing
