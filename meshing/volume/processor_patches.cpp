#include "meshing/volume/processor_patches.hpp"

#include <fmt/format.h>

#include "core/point_key.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

namespace bedforge::meshing {

ProcessorPatch processor_patch(int piece, int neighbour) {
  ProcessorPatch p;
  p.patch.name = fmt::format("procBoundary{}to{}", piece, neighbour);
  p.patch.type = "processor";
  p.patch.processor = piece;
  p.patch.neighbour_processor = neighbour;
  return p;
}

void order_processor_faces(const std::vector<Eigen::Vector3d>& points, ProcessorPatch& p) {
  using Key = std::array<double, 3>;
  std::vector<std::vector<Key>> keys(p.faces.size());
  for (std::size_t f = 0; f < p.faces.size(); ++f) {
    std::vector<int>& face = p.faces[f];
    std::rotate(face.begin(),
                std::min_element(face.begin(), face.end(),
                                 [&](int a, int b) { return coordinates_less(points[a], points[b]); }),
                face.end());
    for (int v : face) keys[f].push_back({points[v].x(), points[v].y(), points[v].z()});
    std::sort(keys[f].begin(), keys[f].end());
  }
  std::vector<std::size_t> order(p.faces.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
  ProcessorPatch sorted{p.patch, {}, {}};
  for (std::size_t f : order) sorted.faces.push_back(std::move(p.faces[f])), sorted.owner.push_back(p.owner[f]);
  p = std::move(sorted);
}

void make_processor_patches(PolyMesh& m, int piece, int pieces) {
  if (piece < 0 || piece >= pieces)
    throw std::runtime_error(fmt::format("processor patches: piece {} of {} does not exist", piece, pieces));
  const int inlet = patch_number(m, "inlet"), outlet = patch_number(m, "outlet");
  std::vector<ProcessorPatch> out;
  ProcessorPatch below = processor_patch(piece, piece - 1), above = processor_patch(piece, piece + 1);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k) {
    ProcessorPatch kept{m.patches[k], {}, {}};
    ProcessorPatch& to = k == inlet && piece > 0 ? below : k == outlet && piece + 1 < pieces ? above : kept;
    for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f) {
      to.faces.push_back(points_of(m, f));
      to.owner.push_back(m.owner[f]);
    }
    out.push_back(std::move(kept));
  }
  // A shared plane's faces alike on both sides (on the plane, by x and y).
  order_processor_faces(m.points, below);
  order_processor_faces(m.points, above);
  if (piece > 0) out.push_back(std::move(below));
  if (piece + 1 < pieces) out.push_back(std::move(above));
  // The boundary written anew, patch after patch.
  const int internal = m.internal_faces();
  m.faces.resize(internal);
  m.owner.resize(internal);
  m.patches.clear();
  for (ProcessorPatch& p : out) {
    p.patch.start = static_cast<int>(m.owner.size());
    p.patch.size = static_cast<int>(p.faces.size());
    for (std::size_t f = 0; f < p.faces.size(); ++f) {
      Face face;
      face.n = static_cast<int>(p.faces[f].size());
      std::copy(p.faces[f].begin(), p.faces[f].end(), face.v.begin());
      m.faces.push_back(face);
      m.owner.push_back(p.owner[f]);
    }
    m.patches.push_back(p.patch);
  }
}

}  // namespace bedforge::meshing
