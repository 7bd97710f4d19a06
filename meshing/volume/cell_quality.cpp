#include "meshing/volume/cell_quality.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <fstream>
#include <numbers>
#include <unordered_map>

namespace bedforge::meshing {

namespace {

constexpr double kRootVSmall = 1e-150;  // OpenFOAM's ROOTVSMALL, guards divisions as it does

// Face f's point labels in place, whichever way the mesh stores its faces.
std::span<const int> face_points(const PolyMesh& m, int f) { return {m.faces[f].begin(), m.faces[f].end()}; }
std::span<const int> face_points(const PolyhedralMesh& m, int f) { return m.faces[f]; }

template <class Mesh>
CellQuality cell_quality_of(const Mesh& m) {
  CellQuality q;
  CellGeometry geometry = cell_geometry(m);
  const std::vector<Eigen::Vector3d>& cc = geometry.centres;
  q.volume = std::move(geometry.volumes);
  q.non_orthogonality_deg.assign(m.cells, 0.0);
  q.skewness.assign(m.cells, 0.0);
  q.aspect_ratio.assign(m.cells, 0.0);
  q.min_face_pyramid.assign(m.cells, std::numeric_limits<double>::max());
  q.non_orthogonality_histogram.assign(9, 0);
  std::vector<Eigen::Vector3d> sum_mag_area(m.cells, Eigen::Vector3d::Zero());
  double sum_cos = 0.0;

  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const int own = m.owner[f];
    const bool internal = f < m.neighbour.size();
    const int nei = internal ? m.neighbour[f] : -1;
    const FaceFigures ff = face_figures(m.points, face_points(m, static_cast<int>(f)), cc[own], internal ? &cc[nei] : nullptr);
    sum_mag_area[own] += ff.area.cwiseAbs();
    q.max_skewness = std::max(q.max_skewness, ff.skewness);
    for (const auto& [cell, pyramid] : {std::pair{own, ff.pyramid_owner}, std::pair{nei, ff.pyramid_neighbour}}) {
      if (cell < 0) continue;
      q.min_face_pyramid[cell] = std::min(q.min_face_pyramid[cell], pyramid);
      q.inverted_face_pyramids += pyramid < 0.0;
      q.skewness[cell] = std::max(q.skewness[cell], ff.skewness);
    }
    if (!internal) continue;
    sum_mag_area[nei] += ff.area.cwiseAbs();
    const double angle = ff.non_orthogonality_deg;
    sum_cos += std::cos(angle * std::numbers::pi / 180.0);
    q.max_non_orthogonality_deg = std::max(q.max_non_orthogonality_deg, angle);
    if (angle > 70.0) ++q.faces_over_70_deg;
    ++q.non_orthogonality_histogram[std::min(8, static_cast<int>(angle / 10.0))];
    q.non_orthogonality_deg[own] = std::max(q.non_orthogonality_deg[own], angle);
    q.non_orthogonality_deg[nei] = std::max(q.non_orthogonality_deg[nei], angle);
  }

  q.min_volume = q.volume.empty() ? 0.0 : q.volume[0];
  for (int c = 0; c < m.cells; ++c) {
    const Eigen::Vector3d& s = sum_mag_area[c];
    double ar = s.maxCoeff() / (s.minCoeff() + kRootVSmall);
    const double v = std::max(kRootVSmall, q.volume[c]);
    ar = std::max(ar, s.sum() / 6.0 / std::pow(v, 2.0 / 3.0));
    q.aspect_ratio[c] = ar;
    q.max_aspect_ratio = std::max(q.max_aspect_ratio, ar);
    q.min_volume = std::min(q.min_volume, q.volume[c]);
    q.total_volume += q.volume[c];
  }
  // checkMesh's "average" is the angle of the mean cosine, not the mean angle.
  if (!m.neighbour.empty())
    q.mean_non_orthogonality_deg = std::acos(sum_cos / static_cast<double>(m.neighbour.size())) * 180.0 / std::numbers::pi;
  return q;
}

// Legacy VTK of the given cells as the polygons of their faces (any cell type, PolyMesh or
// PolyhedralMesh), each carrying its cell's quality and nearest particle, for ParaView.
template <class Mesh>
void write_bad_cells(const std::filesystem::path& path, const Mesh& m, const CellQuality& q,
                     const std::vector<int>& bad, const std::vector<int>& nearest) {
  std::unordered_map<int, int> rank;  // cell -> position in `bad`
  for (std::size_t k = 0; k < bad.size(); ++k) rank.emplace(bad[k], static_cast<int>(k));
  std::vector<std::pair<int, int>> polygons;  // (position in bad, face)
  for (std::size_t f = 0; f < m.owner.size(); ++f)
    for (int c : {m.owner[f], f < m.neighbour.size() ? m.neighbour[f] : -1})
      if (const auto it = rank.find(c); c >= 0 && it != rank.end()) polygons.emplace_back(it->second, static_cast<int>(f));
  std::sort(polygons.begin(), polygons.end());
  std::size_t corners = 0;
  for (const auto& [k, f] : polygons) corners += points_of(m, f).size();
  std::ofstream out(path);
  out << "# vtk DataFile Version 3.0\nbedforge cells failing the quality gate, as their faces\nASCII\nDATASET POLYDATA\n";
  out << "POINTS " << corners << " double\n";
  for (const auto& [k, f] : polygons)
    for (int v : points_of(m, f))
      out << fmt::format("{:.12g} {:.12g} {:.12g}\n", m.points[v].x(), m.points[v].y(), m.points[v].z());
  out << "POLYGONS " << polygons.size() << " " << polygons.size() + corners << "\n";
  std::size_t next = 0;
  for (const auto& [k, f] : polygons) {
    const std::size_t n = points_of(m, f).size();
    out << n;
    for (std::size_t j = 0; j < n; ++j) out << " " << next++;
    out << "\n";
  }
  out << "CELL_DATA " << polygons.size() << "\n";
  auto field = [&](const char* name, const auto& value) {
    out << "SCALARS " << name << " double 1\nLOOKUP_TABLE default\n";
    for (const auto& [k, f] : polygons) out << fmt::format("{:.6g}\n", static_cast<double>(value(k)));
  };
  field("cell", [&](int k) { return bad[k]; });
  field("non_orthogonality_deg", [&](int k) { return q.non_orthogonality_deg[bad[k]]; });
  field("skewness", [&](int k) { return q.skewness[bad[k]]; });
  field("aspect_ratio", [&](int k) { return q.aspect_ratio[bad[k]]; });
  field("volume_m3", [&](int k) { return q.volume[bad[k]]; });
  field("min_face_pyramid_m3", [&](int k) { return q.min_face_pyramid[bad[k]]; });
  field("nearest_particle", [&](int k) { return nearest[k]; });
}

template <class Mesh>
DefectLocations locate_bad_cells_of(const Bed& bed, const Mesh& m, const CellQuality& q, const std::vector<int>& bad,
                                    const std::filesystem::path& path) {
  const std::vector<Eigen::Vector3d> centres = cell_geometry(m).centres;
  std::vector<Eigen::Vector3d> at;
  for (int c : bad) at.push_back(centres[c]);
  DefectLocations where = locate_defects(bed, at, "cells");
  if (!path.empty()) write_bad_cells(path, m, q, bad, where.nearest);
  return where;
}

}  // namespace

FaceFigures face_figures(const std::vector<Eigen::Vector3d>& points, std::span<const int> face,
                         const Eigen::Vector3d& owner_centre, const Eigen::Vector3d* neighbour_centre) {
  FaceFigures out;
  const auto [fc, area] = face_geometry(points, face);
  out.area = area;
  const Eigen::Vector3d cpf = fc - owner_centre;
  // Face pyramids as primitiveMeshTools::facePyramidVolume: the face seen from each of its
  // cells' centres, positive when the face points away from that centre.
  out.pyramid_owner = area.dot(cpf) / 3.0;
  Eigen::Vector3d d;
  if (neighbour_centre) {
    out.pyramid_neighbour = area.dot(*neighbour_centre - fc) / 3.0;
    d = *neighbour_centre - owner_centre;
    const double c = std::clamp(d.dot(area) / (d.norm() * area.norm() + kRootVSmall), -1.0, 1.0);
    out.non_orthogonality_deg = std::acos(c) * 180.0 / std::numbers::pi;
  } else {
    const Eigen::Vector3d n = area / (area.norm() + kRootVSmall);
    d = n * n.dot(cpf);
  }
  // Skewness as primitiveMeshTools::faceSkewness / boundaryFaceSkewness; a boundary face's d
  // reaches only from the cell to the face, half an internal face's, hence 0.4 for 0.2.
  const Eigen::Vector3d sv = neighbour_centre
                                 ? Eigen::Vector3d(cpf - (area.dot(cpf) / (area.dot(d) + kRootVSmall)) * d)
                                 : Eigen::Vector3d(cpf - d);
  const Eigen::Vector3d sv_hat = sv / (sv.norm() + kRootVSmall);
  double fd = (neighbour_centre ? 0.2 : 0.4) * d.norm() + kRootVSmall;
  for (int v : face) fd = std::max(fd, std::abs(sv_hat.dot(points[v] - fc)));
  out.skewness = sv.norm() / fd;
  return out;
}

bool FaceFigures::fails(const QualityGate& gate) const {
  return non_orthogonality_deg > gate.max_non_orthogonality_deg || skewness > gate.max_skewness ||
         pyramid_owner < gate.min_face_pyramid_m3 || pyramid_neighbour < gate.min_face_pyramid_m3;
}

CellQuality cell_quality(const PolyMesh& mesh) { return cell_quality_of(mesh); }
CellQuality cell_quality(const PolyhedralMesh& mesh) { return cell_quality_of(mesh); }

std::vector<int> CellQuality::bad_cells(const QualityGate& gate, double d_ref) const {
  std::vector<int> bad;
  const double min_vol = gate.min_volume_d3 * d_ref * d_ref * d_ref;
  for (std::size_t c = 0; c < volume.size(); ++c)
    if (non_orthogonality_deg[c] > gate.max_non_orthogonality_deg || skewness[c] > gate.max_skewness ||
        aspect_ratio[c] > gate.max_aspect_ratio || volume[c] < min_vol || min_face_pyramid[c] < gate.min_face_pyramid_m3)
      bad.push_back(static_cast<int>(c));
  return bad;
}

nlohmann::json CellQuality::to_json(double d_ref) const {
  return {{"max_non_orthogonality_deg", max_non_orthogonality_deg},
          {"mean_non_orthogonality_deg", mean_non_orthogonality_deg},
          {"faces_over_70_deg", faces_over_70_deg},
          {"non_orthogonality_histogram_10deg", non_orthogonality_histogram},
          {"max_skewness", max_skewness},
          {"max_aspect_ratio", max_aspect_ratio},
          {"min_volume_d3", min_volume / (d_ref * d_ref * d_ref)},
          {"inverted_face_pyramids", inverted_face_pyramids},
          {"volume_m3", total_volume}};
}

DefectLocations locate_bad_cells(const Bed& bed, const PolyMesh& m, const CellQuality& q, const std::vector<int>& bad,
                                 const std::filesystem::path& path) {
  return locate_bad_cells_of(bed, m, q, bad, path);
}
DefectLocations locate_bad_cells(const Bed& bed, const PolyhedralMesh& m, const CellQuality& q,
                                 const std::vector<int>& bad, const std::filesystem::path& path) {
  return locate_bad_cells_of(bed, m, q, bad, path);
}

}  // namespace bedforge::meshing
