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
  return mesh.patches[bedforge::meshing::patch_number(mesh, name)];
}

// The processor patches of pieces k and k + 1 that face each other: procBoundary<k>to<k+1> of
// `lower` and procBoundary<k+1>to<k> of `upper`; std::runtime_error unless each names the
// other's processor and they hold as many faces.
template <class Mesh>
std::pair<const bedforge::meshing::PolyMesh::Patch&, const bedforge::meshing::PolyMesh::Patch&> facing_patches(
    const Mesh& lower, const Mesh& upper, int k) {
  const auto& a = patch_named(lower, "procBoundary" + std::to_string(k) + "to" + std::to_string(k + 1));
  const auto& c = patch_named(upper, "procBoundary" + std::to_string(k + 1) + "to" + std::to_string(k));
  if (a.neighbour_processor != k + 1 || c.neighbour_processor != k || a.size != c.size)
    throw std::runtime_error("the processor patches between pieces " + std::to_string(k) + " and " +
                             std::to_string(k + 1) + " do not face each other: neighbours " +
                             std::to_string(a.neighbour_processor) + " and " + std::to_string(c.neighbour_processor) +
                             ", " + std::to_string(a.size) + " and " + std::to_string(c.size) + " faces");
  return {a, c};
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

// How many faces of the facing patches `a` of `lower` and `c` of `upper` (facing_patches) are
// not one face seen from either side.
template <class Mesh>
long mismatched_faces(const Mesh& lower, const bedforge::meshing::PolyMesh::Patch& a, const Mesh& upper,
                      const bedforge::meshing::PolyMesh::Patch& c) {
  long mismatched = 0;
  for (int f = 0; f < a.size; ++f) mismatched += !same_face_reversed(lower, a.start + f, upper, c.start + f);
  return mismatched;
}

}  // namespace test_support
