#include "meshing/volume/processor_patches.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/binary_io.hpp"
#include "core/error.hpp"
#include "core/point_key.hpp"

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

namespace {

constexpr char kFacesMagic[] = "bedforge processor faces 1\n";

template <class Mesh>
std::vector<ProcessorFaces> processor_faces_of(const Mesh& m) {
  std::vector<ProcessorFaces> out;
  for (const auto& p : m.patches) {
    if (p.type != "processor") continue;
    ProcessorFaces& side = out.emplace_back();
    side.processor = p.processor, side.neighbour = p.neighbour_processor;
    for (int f = p.start; f < p.start + p.size; ++f) {
      const std::vector<int> face = points_of(m, f);
      const FaceGeometry g = face_geometry(m.points, std::span<const int>(face));
      double size = 0.0;
      for (int v : face) size = std::max(size, (m.points[v] - g.centre).norm());
      side.centres.push_back(g.centre), side.areas.push_back(g.area), side.sizes.push_back(size);
    }
  }
  return out;
}

}  // namespace

std::vector<ProcessorFaces> processor_faces(const PolyMesh& mesh) { return processor_faces_of(mesh); }
std::vector<ProcessorFaces> processor_faces(const PolyhedralMesh& mesh) { return processor_faces_of(mesh); }

void write_processor_faces(const std::filesystem::path& path, const std::vector<ProcessorFaces>& patches) {
  write_file_atomically(path, [&](std::ostream& out) {
    out.write(kFacesMagic, sizeof kFacesMagic - 1);
    put_vector(out, std::vector<std::uint64_t>{patches.size()});
    for (const ProcessorFaces& p : patches) {
      put_vector(out, std::vector<std::int32_t>{p.processor, p.neighbour});
      put_vector(out, p.centres), put_vector(out, p.areas), put_vector(out, p.sizes);
    }
  });
}

std::vector<ProcessorFaces> read_processor_faces(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic(sizeof kFacesMagic - 1, '\0');
  std::vector<std::uint64_t> count;
  bool ok = in.read(magic.data(), static_cast<std::streamsize>(magic.size())) && magic == kFacesMagic &&
            get_vector(in, count) && count.size() == 1 && count[0] < 1000;
  std::vector<ProcessorFaces> out(ok ? count[0] : 0);
  for (ProcessorFaces& p : out) {
    std::vector<std::int32_t> ids;
    ok = ok && get_vector(in, ids) && ids.size() == 2 && get_vector(in, p.centres) && get_vector(in, p.areas) &&
         get_vector(in, p.sizes) && p.areas.size() == p.centres.size() && p.sizes.size() == p.centres.size();
    if (ok) p.processor = ids[0], p.neighbour = ids[1];
  }
  if (!ok) throw InputError(fmt::format("{}: not a piece's processor faces as bedforge writes them, or cut short",
                                        path.string()));
  return out;
}

ProcessorMismatch compare_processor_faces(const ProcessorFaces& mine, const ProcessorFaces& theirs) {
  constexpr double kMatch = 1e-4;  // OpenFOAM's coupledPolyPatch::defaultMatchTol_
  ProcessorMismatch out;
  const std::size_t n = std::min(mine.centres.size(), theirs.centres.size());
  std::string first;
  for (std::size_t k = 0; k < n; ++k) {
    const double size = std::max(mine.sizes[k], theirs.sizes[k]);
    const double apart = (mine.centres[k] - theirs.centres[k]).norm();
    const double area = mine.areas[k].norm(), their_area = theirs.areas[k].norm();
    if (apart <= kMatch * size && std::abs(area - their_area) <= kMatch * size * size &&
        mine.areas[k].dot(theirs.areas[k]) < 0.0)
      continue;
    if (out.faces.empty())
      first = fmt::format("face {} at ({:.6g}, {:.6g}, {:.6g}) m: its copy lies {:.3g} m away ({:.3g} of the "
                          "face's size), area {:.6g} against {:.6g} m^2, normals {}",
                          k, mine.centres[k].x(), mine.centres[k].y(), mine.centres[k].z(), apart,
                          size > 0.0 ? apart / size : 0.0, area, their_area,
                          mine.areas[k].dot(theirs.areas[k]) < 0.0 ? "opposed" : "not opposed");
    out.faces.push_back(static_cast<int>(k));
  }
  const std::string patch = fmt::format("procBoundary{}to{}", mine.processor, mine.neighbour);
  if (mine.centres.size() != theirs.centres.size())
    out.what = fmt::format("{} has {} faces, procBoundary{}to{} {}", patch, mine.centres.size(), theirs.processor,
                           theirs.neighbour, theirs.centres.size());
  if (!out.faces.empty())
    out.what += fmt::format("{}{} of {}'s {} faces do not match their copies across the plane (first: {})",
                            out.what.empty() ? "" : "; ", out.faces.size(), patch, mine.centres.size(), first);
  return out;
}

void write_processor_mismatch(const std::filesystem::path& path, const ProcessorFaces& mine,
                              const ProcessorFaces& theirs, const ProcessorMismatch& mismatch) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "face,x,y,z,x_copy,y_copy,z_copy,area_m2,area_copy_m2,size_m\n";
    for (int k : mismatch.faces)
      out << fmt::format("{},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.12g},{:.6g},{:.6g},{:.6g}\n", k,
                         mine.centres[k].x(), mine.centres[k].y(), mine.centres[k].z(), theirs.centres[k].x(),
                         theirs.centres[k].y(), theirs.centres[k].z(), mine.areas[k].norm(), theirs.areas[k].norm(),
                         std::max(mine.sizes[k], theirs.sizes[k]));
  });
}

}  // namespace bedforge::meshing
