#include "meshing/volume/dual_pieces.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "core/atomic_file.hpp"
#include "core/binary_io.hpp"
#include "core/error.hpp"
#include "core/point_key.hpp"
#include "meshing/volume/processor_patches.hpp"

namespace bedforge::meshing {

namespace {

constexpr char kMagic[] = "bedforge plane layer 1\n";

// The layer file's magic and tag into `tag`; false when it is not there.
bool read_layer_header(std::istream& in, std::string& tag) {
  std::string magic(sizeof kMagic - 1, '\0');
  return in.read(magic.data(), static_cast<std::streamsize>(magic.size())) && magic == kMagic && get_string(in, tag);
}

InputError not_a_layer(const std::filesystem::path& path) {
  return InputError(fmt::format("{}: not a plane layer bedforge wrote, or cut short", path.string()));
}

}  // namespace

PlaneLayer plane_layer(const PolyMesh& m, const std::string& plane, int rings) {
  const int on_plane = patch_number(m, plane);
  const std::vector<VolumeCell> tets = tetrahedra(m);
  // Ring by ring: the tetrahedra touching the plane, then those touching their points, ...
  std::vector<char> ring(m.points.size(), 0), in(tets.size(), 0);
  const PolyMesh::Patch& p = m.patches[on_plane];
  for (int f = p.start; f < p.start + p.size; ++f)
    for (int v : m.faces[f]) ring[v] = 1;
  for (int round = 0, grew = 1; round < rings && grew; ++round) {
    grew = 0;
    for (std::size_t c = 0; c < tets.size(); ++c)
      if (!in[c] && std::any_of(tets[c].v.begin(), tets[c].v.begin() + tets[c].n, [&](int v) { return ring[v]; }))
        in[c] = 1, grew = 1;
    for (std::size_t c = 0; c < tets.size(); ++c)
      if (in[c])
        for (int j = 0; j < tets[c].n; ++j) ring[tets[c].v[j]] = 1;
  }
  PlaneLayer layer;
  std::vector<int> local(m.points.size(), -1);
  auto to_local = [&](int v) {
    if (local[v] < 0) local[v] = static_cast<int>(layer.points.size()), layer.points.push_back(m.points[v]);
    return local[v];
  };
  for (std::size_t c = 0; c < tets.size(); ++c) {
    if (!in[c]) continue;
    VolumeCell cell = tets[c];
    for (int j = 0; j < cell.n; ++j) cell.v[j] = to_local(cell.v[j]);
    layer.cells.push_back(cell);
  }
  auto add_face = [&](const Face& face, int patch) {
    Face f = face;
    for (int& v : f) v = to_local(v);
    layer.boundary.push_back(f);
    layer.patch.push_back(patch);
  };
  for (const auto& q : m.patches) layer.names.push_back(q.name);
  layer.names.push_back(kLayerEdge);
  const int edge = static_cast<int>(layer.names.size()) - 1;
  for (int f = 0; f < m.internal_faces(); ++f)
    if (in[m.owner[f]] != in[m.neighbour[f]]) add_face(m.faces[f], edge);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k)
    if (k != on_plane)
      for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f)
        if (in[m.owner[f]]) add_face(m.faces[f], k);
  return layer;
}

PlaneLayer whole_slab(const PolyMesh& m) {
  PlaneLayer all;
  all.points = m.points;
  all.cells = tetrahedra(m);
  for (int k = 0; k < static_cast<int>(m.patches.size()); ++k) {
    all.names.push_back(m.patches[k].name);
    for (int f = m.patches[k].start; f < m.patches[k].start + m.patches[k].size; ++f)
      all.boundary.push_back(m.faces[f]), all.patch.push_back(k);
  }
  return all;
}

PolyMesh slab_of(const PlaneLayer& all) {
  std::vector<std::string> types;
  for (const auto& name : all.names) types.push_back(patch_type(name));
  return poly_mesh_from_cells(all.points, all.cells, all.boundary, all.patch, all.names, types);
}

void write_plane_layer(const std::filesystem::path& path, const PlaneLayer& layer) {
  write_file_atomically(path, [&](std::ostream& out) {
    out.write(kMagic, sizeof kMagic - 1);
    put_string(out, layer.tag);
    const std::uint64_t names = layer.names.size();
    out.write(reinterpret_cast<const char*>(&names), sizeof names);
    for (const auto& n : layer.names) put_string(out, n);
    put_vector(out, layer.points);
    put_vector(out, layer.cells);
    put_vector(out, layer.boundary);
    put_vector(out, layer.patch);
  });
}

std::string read_plane_layer_tag(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string tag;
  if (!read_layer_header(in, tag)) throw not_a_layer(path);
  return tag;
}

PlaneLayer read_plane_layer(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  PlaneLayer layer;
  std::uint64_t names = 0;
  bool ok = read_layer_header(in, layer.tag) && in.read(reinterpret_cast<char*>(&names), sizeof names) && names < 1000;
  for (std::uint64_t k = 0; ok && k < names; ++k) ok = get_string(in, layer.names.emplace_back());
  ok = ok && get_vector(in, layer.points) && get_vector(in, layer.cells) && get_vector(in, layer.boundary) &&
       get_vector(in, layer.patch) && layer.patch.size() == layer.boundary.size();
  if (!ok) throw not_a_layer(path);
  return layer;
}

SlabWithLayers slab_with_layers(const PolyMesh& slab, const PlaneLayer* below, const PlaneLayer* above) {
  std::vector<Eigen::Vector3d> points = slab.points;
  std::vector<int> side(points.size(), 0);
  std::vector<VolumeCell> cells = tetrahedra(slab);
  std::vector<Face> boundary;
  std::vector<int> patch;
  std::vector<std::string> names, types;
  for (const auto& p : slab.patches) names.push_back(p.name), types.push_back(p.type);
  auto name_index = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return static_cast<int>(it - names.begin());
    names.push_back(name);
    types.push_back(name == kLayerEdge ? "patch" : patch_type(name));
    return static_cast<int>(names.size()) - 1;
  };
  const int inlet = patch_number(slab, "inlet"), outlet = patch_number(slab, "outlet");
  // The slab's own boundary, but for the planes the layers close.
  for (int k = 0; k < static_cast<int>(slab.patches.size()); ++k) {
    if ((k == inlet && below) || (k == outlet && above)) continue;
    for (int f = slab.patches[k].start; f < slab.patches[k].start + slab.patches[k].size; ++f)
      boundary.push_back(slab.faces[f]), patch.push_back(k);
  }
  for (const auto& [layer, plane, s] : {std::tuple{below, inlet, -1}, std::tuple{above, outlet, 1}}) {
    if (!layer) continue;
    // The shared plane's points, bit for bit the same on both sides.
    std::unordered_map<PointKey, int, PointKeyHash> at;
    const PolyMesh::Patch& p = slab.patches[plane];
    for (int f = p.start; f < p.start + p.size; ++f)
      for (int v : slab.faces[f]) {
        at.emplace(PointKey(slab.points[v]), v);
        if (s < 0) side[v] = -1;
      }
    std::vector<int> global(layer->points.size());
    std::size_t matched = 0;
    for (std::size_t i = 0; i < layer->points.size(); ++i) {
      const auto it = at.find(PointKey(layer->points[i]));
      if (it != at.end()) {
        global[i] = it->second, ++matched;
      } else {
        global[i] = static_cast<int>(points.size());
        points.push_back(layer->points[i]);
        side.push_back(s);
      }
    }
    if (matched != at.size())
      throw std::runtime_error(fmt::format(
          "dual pieces: the layer of the piece {} has {} of the {} points of their shared plane (from another run or "
          "bed?)",
          s < 0 ? "below" : "above", matched, at.size()));
    for (VolumeCell c : layer->cells) {
      for (int j = 0; j < c.n; ++j) c.v[j] = global[c.v[j]];
      cells.push_back(c);
    }
    for (std::size_t b = 0; b < layer->boundary.size(); ++b) {
      Face f = layer->boundary[b];
      for (int& v : f) v = global[v];
      boundary.push_back(f);
      patch.push_back(name_index(layer->names[layer->patch[b]]));
    }
  }
  SlabWithLayers out;
  std::vector<int> point_map;
  out.mesh = poly_mesh_from_cells(std::move(points), cells, boundary, patch, names, types, &point_map);
  out.side.assign(out.mesh.points.size(), 0);
  for (std::size_t v = 0; v < point_map.size(); ++v)
    if (point_map[v] >= 0) out.side[point_map[v]] = side[v];
  return out;
}

std::vector<Eigen::Vector3d> tetrahedron_centroids(const PolyMesh& m) {
  const std::vector<VolumeCell> tets = tetrahedra(m);
  std::vector<Eigen::Vector3d> out(tets.size());
  for (std::size_t c = 0; c < tets.size(); ++c) {
    std::array<Eigen::Vector3d, 4> t;
    for (int j = 0; j < 4; ++j) t[j] = m.points[tets[c].v[j]];
    std::sort(t.begin(), t.end(), coordinates_less);
    out[c] = ((t[0] + t[1]) + (t[2] + t[3])) * 0.25;
  }
  return out;
}

PolyhedralMesh dual_piece(const PolyhedralMesh& d, const std::vector<int>& cell_points, const std::vector<int>& side,
                          int piece, int pieces) {
  if (piece < 0 || piece >= pieces)
    throw std::runtime_error(fmt::format("dual pieces: piece {} of {} does not exist", piece, pieces));
  std::vector<int> cell(d.cells, -1);
  int kept = 0;
  for (int c = 0; c < d.cells; ++c)
    if (side[cell_points[c]] == 0) cell[c] = kept++;
  PolyhedralMesh out;
  out.cells = kept;
  std::vector<int> point(d.points.size(), -1);
  auto add_face = [&](std::vector<int> face, int owner) {
    for (int& v : face) {
      if (point[v] < 0) point[v] = static_cast<int>(out.points.size()), out.points.push_back(d.points[v]);
      v = point[v];
    }
    out.faces.push_back(face);
    out.owner.push_back(owner);
  };
  // Internal faces between the piece's cells, in their order (still upper-triangular); the
  // faces towards a neighbour's cells, turned to point out of the piece's (in d's points).
  std::array<ProcessorPatch, 2> towards{processor_patch(piece, piece - 1), processor_patch(piece, piece + 1)};
  for (int f = 0; f < d.internal_faces(); ++f) {
    const int a = cell[d.owner[f]], b = cell[d.neighbour[f]];
    if (a >= 0 && b >= 0) {
      add_face(points_of(d, f), a);
      out.neighbour.push_back(b);
    } else if (a >= 0 || b >= 0) {
      const int s = side[cell_points[a >= 0 ? d.neighbour[f] : d.owner[f]]];
      if ((s < 0 && piece == 0) || (s > 0 && piece + 1 == pieces))
        throw std::runtime_error(fmt::format("dual pieces: piece {} of {} has a face towards a piece {} it, and there is none",
                                             piece, pieces, s < 0 ? "below" : "above"));
      std::vector<int> face = points_of(d, f);
      if (a < 0) std::reverse(face.begin(), face.end());
      towards[s > 0].faces.push_back(std::move(face));
      towards[s > 0].owner.push_back(a >= 0 ? a : b);
    }
  }
  for (const PolyMesh::Patch& p : d.patches) {
    const bool edge = p.name == kLayerEdge;
    PolyMesh::Patch q = p;
    q.start = static_cast<int>(out.faces.size());
    for (int f = p.start; f < p.start + p.size; ++f) {
      if (cell[d.owner[f]] < 0) continue;
      if (edge) {
        const Eigen::Vector3d at = face_geometry(d.points, d.faces[f]).centre;
        throw std::runtime_error(fmt::format(
            "dual pieces: a cell of piece {} reaches the edge of a neighbour's layer at ({:.6g}, {:.6g}, {:.6g}) m",
            piece, at.x(), at.y(), at.z()));
      }
      add_face(points_of(d, f), cell[d.owner[f]]);
    }
    q.size = static_cast<int>(out.faces.size()) - q.start;
    if (!edge) out.patches.push_back(q);
  }
  // The processor patches, their faces in the order both sides agree on.
  for (ProcessorPatch& p : towards) {
    if (p.patch.neighbour_processor < 0 || p.patch.neighbour_processor >= pieces) continue;
    order_processor_faces(d.points, p);
    p.patch.start = static_cast<int>(out.faces.size());
    for (std::size_t f = 0; f < p.faces.size(); ++f) add_face(std::move(p.faces[f]), p.owner[f]);
    p.patch.size = static_cast<int>(out.faces.size()) - p.patch.start;
    out.patches.push_back(p.patch);
  }
  return out;
}

}  // namespace bedforge::meshing
