#pragma once
// Helpers for tests of the pieces of a decomposed case (processor patches).
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "meshing/volume/poly_mesh.hpp"

namespace test_support {

// The patch of `mesh` called `name`; std::runtime_error when there is none.
template <class Mesh>
const bedforge::meshing::PolyMesh::Patch& patch_named(const Mesh& mesh, const std::string& name) {
  for (const auto& p : mesh.patches)
    if (p.name == name) return p;
  throw std::runtime_error("no patch " + name);
}

// The processor patches of pieces k and k + 1 that face each other: procBoundary<k>to<k+1> of
// `lower` and procBoundary<k+1>to<k> of `upper`.
template <class Mesh>
std::pair<const bedforge::meshing::PolyMesh::Patch&, const bedforge::meshing::PolyMesh::Patch&> facing_patches(
    const Mesh& lower, const Mesh& upper, int k) {
  return {patch_named(lower, "procBoundary" + std::to_string(k) + "to" + std::to_string(k + 1)),
          patch_named(upper, "procBoundary" + std::to_string(k + 1) + "to" + std::to_string(k))};
}

// Whether face `fa` of `a` and face `fb` of `b` are one face seen from either side, as decomposePar
// writes a processor patch's copy: the same points bit for bit, from the same 0th, in reverse order.
template <class Mesh>
bool same_face_reversed(const Mesh& a, int fa, const Mesh& b, int fb) {
  const std::vector<int> x = bedforge::meshing::points_of(a, fa), y = bedforge::meshing::points_of(b, fb);
  if (x.size() != y.size()) return false;
  for (std::size_t j = 0; j < x.size(); ++j)
    if (a.points[x[j]] != b.points[y[(x.size() - j) % x.size()]]) return false;
  return true;
}

}  // namespace test_support
