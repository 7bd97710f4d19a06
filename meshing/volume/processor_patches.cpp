#include "meshing/volume/processor_patches.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

namespace bedforge::meshing {

namespace {

// Keeps the first `n` faces and appends `face`.
void truncate_faces(PolyMesh& m, int n) { m.faces.resize(n); }
void truncate_faces(PolyhedralMesh& m, int n) {
  m.faces.points.resize(m.faces.offsets[n]);
  m.faces.offsets.resize(n + 1);
}
void append_face(PolyMesh& m, const std::vector<int>& face) {
  Face f;
  f.n = static_cast<int>(face.size());
  std::copy(face.begin(), face.end(), f.v.begin());
  m.faces.push_back(f);
}
void append_face(PolyhedralMesh& m, const std::vector<int>& face) { m.faces.push_back(face); }

// A boundary patch as it will be written: its faces (points) and their cells.
struct NewPatch {
  PolyMesh::Patch patch;
  std::vector<std::vector<int>> faces;
  std::vector<int> owner;
};

}  // namespace

template <class Mesh>
void make_processor_patches(Mesh& m, int piece, int pieces) {
  if (piece < 0 || piece >= pieces)
    throw std::runtime_error(fmt::format("processor patches: piece {} of {} does not exist", piece, pieces));
  auto index = [&](const std::string& name) {
    for (std::size_t k = 0; k < m.patches.size(); ++k)
      if (m.patches[k].name == name) return static_cast<int>(k);
    throw std::runtime_error(fmt::format("processor patches: piece {} has no {} patch", piece, name));
  };
  const int inlet = index("inlet"), outlet = index("outlet");
  using XY = std::pair<double, double>;
  auto xy = [&](int p) { return XY{m.points[p].x(), m.points[p].y()}; };
  std::vector<NewPatch> out;
  NewPatch below, above;
  for (auto [to, p] : {std::pair{&below, piece - 1}, std::pair{&above, piece + 1}}) {
    to->patch.name = fmt::format("procBoundary{}to{}", piece, p);
    to->patch.type = "processor";
    to->patch.processor = piece;
    to->patch.neighbour_processor = p;
  }
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k) {
    NewPatch kept{m.patches[k], {}, {}};
    NewPatch& to = k == inlet && piece > 0 ? below : k == outlet && piece + 1 < pieces ? above : kept;
    for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f) {
      to.faces.push_back(points_of(m, f));
      to.owner.push_back(m.owner[f]);
    }
    out.push_back(std::move(kept));
  }
  // A shared plane's faces in the order of their points' x and y, each from its least point.
  for (NewPatch* p : {&below, &above}) {
    std::vector<std::vector<XY>> keys(p->faces.size());
    for (std::size_t f = 0; f < p->faces.size(); ++f) {
      std::vector<int>& face = p->faces[f];
      const auto least =
          std::min_element(face.begin(), face.end(), [&](int a, int b) { return xy(a) < xy(b); });
      std::rotate(face.begin(), least, face.end());
      for (int v : face) keys[f].push_back(xy(v));
      std::sort(keys[f].begin(), keys[f].end());
    }
    std::vector<std::size_t> order(p->faces.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
    NewPatch sorted{p->patch, {}, {}};
    for (std::size_t f : order) sorted.faces.push_back(std::move(p->faces[f])), sorted.owner.push_back(p->owner[f]);
    *p = std::move(sorted);
  }
  if (piece > 0) out.push_back(std::move(below));
  if (piece + 1 < pieces) out.push_back(std::move(above));
  // The boundary written anew, patch after patch.
  const int internal = m.internal_faces();
  truncate_faces(m, internal);
  m.owner.resize(internal);
  m.patches.clear();
  for (NewPatch& p : out) {
    p.patch.start = static_cast<int>(m.owner.size());
    p.patch.size = static_cast<int>(p.faces.size());
    for (std::size_t f = 0; f < p.faces.size(); ++f) append_face(m, p.faces[f]), m.owner.push_back(p.owner[f]);
    m.patches.push_back(p.patch);
  }
}

template void make_processor_patches(PolyMesh&, int, int);
template void make_processor_patches(PolyhedralMesh&, int, int);

}  // namespace bedforge::meshing
