#include "meshing/volume/cyclic_patches.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace bedforge::meshing {

namespace {

// Replaces the faces first .. first + faces.size() - 1 (a patch's, in place; same total size).
void set_faces(PolyMesh& m, int first, const std::vector<std::vector<int>>& faces) {
  for (std::size_t k = 0; k < faces.size(); ++k)
    for (std::size_t j = 0; j < faces[k].size(); ++j) m.faces[first + k][static_cast<int>(j)] = faces[k][j];
}
void set_faces(PolyhedralMesh& m, int first, const std::vector<std::vector<int>>& faces) {
  int at = m.faces.offsets[first];
  for (std::size_t k = 0; k < faces.size(); ++k) {
    std::copy(faces[k].begin(), faces[k].end(), m.faces.points.begin() + at);
    at += static_cast<int>(faces[k].size());
    m.faces.offsets[first + k + 1] = at;
  }
}

}  // namespace

template <class Mesh>
double match_cyclic_patches(Mesh& m, const std::string& lower_name, const std::string& upper_name, int axis) {
  PolyMesh::Patch& lower = m.patches[patch_number(m, lower_name)];
  PolyMesh::Patch& upper = m.patches[patch_number(m, upper_name)];
  using XY = std::pair<double, double>;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  auto xy = [&](int p) { return XY{m.points[p][u], m.points[p][v]}; };
  // The lower patch's points by their other two coordinates, and each lower face by its sorted points.
  std::map<XY, int> lower_point;
  std::map<std::vector<int>, int> lower_face;
  for (int f = lower.start; f < lower.start + lower.size; ++f) {
    std::vector<int> key = points_of(m, f);
    for (int p : key) lower_point.emplace(xy(p), p);
    std::sort(key.begin(), key.end());
    lower_face.emplace(std::move(key), f);
  }
  if (lower.size != upper.size)
    throw std::runtime_error(fmt::format("cyclic patches: {} has {} faces, {} has {}", lower_name, lower.size,
                                         upper_name, upper.size));
  std::vector<std::vector<int>> faces(upper.size);
  std::vector<int> owner(upper.size, -1);
  long unmatched = 0;
  std::string first;
  for (int f = upper.start; f < upper.start + upper.size; ++f) {
    const std::vector<int> pts = points_of(m, f);
    std::vector<int> twins;
    for (int p : pts) {
      const auto it = lower_point.find(xy(p));
      if (it == lower_point.end()) break;
      twins.push_back(it->second);
    }
    std::vector<int> key = twins;
    std::sort(key.begin(), key.end());
    const auto it = twins.size() == pts.size() ? lower_face.find(key) : lower_face.end();
    if (it == lower_face.end()) {
      if (unmatched++ == 0)
        first = fmt::format("face {} at ({:.6g}, {:.6g}, {:.6g}) m", f, m.points[pts[0]].x(), m.points[pts[0]].y(),
                            m.points[pts[0]].z());
      continue;
    }
    // Face k of the upper patch is the twin of lower face k: start at the twin of its 0th point
    // and run the other way round (its normal points the other way).
    const int k = it->second - lower.start;
    const std::vector<int> lower_pts = points_of(m, it->second);
    const std::size_t n = pts.size();
    const std::size_t start = std::find(twins.begin(), twins.end(), lower_pts[0]) - twins.begin();
    for (std::size_t j = 0; j < n; ++j) {
      faces[k].push_back(pts[(start + j) % n]);
      if (twins[(start + j) % n] != lower_pts[(n - j) % n]) {
        if (unmatched++ == 0) first = fmt::format("face {} (its points run the same way as its twin's)", f);
        break;
      }
    }
    owner[k] = m.owner[f];
  }
  if (unmatched > 0)
    throw std::runtime_error(fmt::format("cyclic patches: {} faces of {} have no twin on {} with the same points in "
                                         "{}{}; the first, {}; please report it with the bed",
                                         unmatched, upper_name, lower_name, "xyz"[u], "xyz"[v], first));
  set_faces(m, upper.start, faces);
  std::copy(owner.begin(), owner.end(), m.owner.begin() + upper.start);
  // Each patch is flat: any point of either gives the period.
  const double period = m.points[points_of(m, upper.start)[0]][axis] - m.points[points_of(m, lower.start)[0]][axis];
  for (auto [p, other, sign] : {std::tuple{&lower, &upper, 1.0}, std::tuple{&upper, &lower, -1.0}}) {
    p->type = "cyclic";
    p->neighbour = other->name;
    p->separation = sign * period * Eigen::Vector3d::Unit(axis);
  }
  return period;
}

template <class Mesh>
int match_every_cyclic_pair(Mesh& m) {
  auto has = [&m](const char* name) {
    return std::any_of(m.patches.begin(), m.patches.end(), [name](const auto& patch) { return patch.name == name; });
  };
  int matched = 0;
  for (const CyclicPair& pair : kCyclicPairs)
    if (has(pair.lower) && has(pair.upper)) match_cyclic_patches(m, pair.lower, pair.upper, pair.axis), ++matched;
  return matched;
}

template double match_cyclic_patches(PolyMesh&, const std::string&, const std::string&, int);
template double match_cyclic_patches(PolyhedralMesh&, const std::string&, const std::string&, int);
template int match_every_cyclic_pair(PolyMesh&);
template int match_every_cyclic_pair(PolyhedralMesh&);

}  // namespace bedforge::meshing
