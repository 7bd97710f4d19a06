#include "meshing/volume/gmsh_model.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace bedforge::meshing {

GmshSession::GmshSession() {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 1);
}

GmshSession::~GmshSession() { gmsh::finalize(); }

PolyMesh extract_poly_mesh() {
  std::vector<std::size_t> node_tags;
  std::vector<double> xyz, uvw;
  gmsh::model::mesh::getNodes(node_tags, xyz, uvw, -1, -1, false, false);
  // gmsh numbers its nodes 1..N: a table, not a hash map, takes a node's tag to its index.
  std::vector<int> index(node_tags.empty() ? 0 : *std::max_element(node_tags.begin(), node_tags.end()) + 1, -1);
  std::vector<Eigen::Vector3d> points(node_tags.size());
  for (std::size_t k = 0; k < node_tags.size(); ++k) {
    index[node_tags[k]] = static_cast<int>(k);
    points[k] = {xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
  }
  node_tags = {}, xyz = {}, uvw = {};
  std::vector<VolumeCell> cells;
  for (const auto& [type, points] : kCellTypes) {
    std::vector<std::size_t> element_tags, element_nodes;
    gmsh::model::mesh::getElementsByType(type, element_tags, element_nodes);
    cells.reserve(cells.size() + element_tags.size());
    for (std::size_t e = 0; e < element_tags.size(); ++e) {
      VolumeCell c;
      c.n = points;
      for (int k = 0; k < points; ++k) c.v[k] = index.at(element_nodes[points * e + k]);
      cells.push_back(c);
    }
  }

  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, 2);
  std::vector<std::string> names, types;
  std::vector<Face> boundary;
  std::vector<int> patch;
  // Patches in a fixed order whatever gmsh's group numbering: inlet, outlet, walls, particles.
  std::vector<std::pair<std::string, int>> named;
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    named.emplace_back(name, tag);
  }
  const std::vector<std::string> order{"inlet", "outlet", "wall", "inner_wall", "particles"};
  auto rank = [&](const std::string& n) { return std::find(order.begin(), order.end(), n) - order.begin(); };
  std::sort(named.begin(), named.end(), [&](const auto& a, const auto& b) {
    return rank(a.first) != rank(b.first) ? rank(a.first) < rank(b.first) : a.first < b.first;
  });
  for (const auto& [name, tag] : named) {
    const int p = static_cast<int>(names.size());
    names.push_back(name);
    types.push_back(patch_type(name));
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(2, tag, entities);
    for (int e : entities) {
      // Fresh vectors each call: gmsh 4.8 leaves a non-empty tag vector at its old size.
      std::vector<std::size_t> triangle_tags, triangle_nodes;
      gmsh::model::mesh::getElementsByType(2, triangle_tags, triangle_nodes, e);
      for (std::size_t t = 0; 3 * t + 2 < triangle_nodes.size(); ++t) {
        boundary.push_back(Face{index.at(triangle_nodes[3 * t]), index.at(triangle_nodes[3 * t + 1]),
                                index.at(triangle_nodes[3 * t + 2])});
        patch.push_back(p);
      }
    }
  }
  return poly_mesh_from_cells(std::move(points), cells, boundary, patch, names, types);
}

PolyMesh read_msh(const std::filesystem::path& msh_path) {
  if (!std::filesystem::exists(msh_path))
    throw InputError(fmt::format("{}: no volume mesh; run `bedforge mesh` on the directory first", msh_path.string()));
  GmshSession session;
  try {
    gmsh::open(msh_path.string());
  } catch (const std::string& e) {
    throw InputError(fmt::format("{}: gmsh cannot read it: {}", msh_path.string(), e));
  }
  return extract_poly_mesh();
}

}  // namespace bedforge::meshing
