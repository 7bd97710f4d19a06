#include "meshing/volume/cell_quality.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bedforge::meshing {

namespace {
constexpr double kRootVSmall = 1e-150;  // OpenFOAM's ROOTVSMALL, guards divisions as it does
}

CellQuality cell_quality(const PolyMesh& m) {
  CellQuality q;
  CellGeometry geometry = cell_geometry(m);
  const std::vector<Eigen::Vector3d>& cc = geometry.centres;
  q.volume = std::move(geometry.volumes);
  q.non_orthogonality_deg.assign(m.cells, 0.0);
  q.skewness.assign(m.cells, 0.0);
  q.aspect_ratio.assign(m.cells, 0.0);
  q.non_orthogonality_histogram.assign(9, 0);
  std::vector<Eigen::Vector3d> sum_mag_area(m.cells, Eigen::Vector3d::Zero());
  double sum_cos = 0.0;

  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto& t = m.faces[f];
    const auto [fc, area] = face_geometry(m.points, t);
    const int own = m.owner[f];
    const bool internal = f < m.neighbour.size();
    sum_mag_area[own] += area.cwiseAbs();
    const Eigen::Vector3d cpf = fc - cc[own];
    Eigen::Vector3d d;
    if (internal) {
      const int nei = m.neighbour[f];
      sum_mag_area[nei] += area.cwiseAbs();
      d = cc[nei] - cc[own];
      const double c = std::clamp(d.dot(area) / (d.norm() * area.norm() + kRootVSmall), -1.0, 1.0);
      const double angle = std::acos(c) * 180.0 / std::numbers::pi;
      sum_cos += c;
      q.max_non_orthogonality_deg = std::max(q.max_non_orthogonality_deg, angle);
      if (angle > 70.0) ++q.faces_over_70_deg;
      ++q.non_orthogonality_histogram[std::min(8, static_cast<int>(angle / 10.0))];
      q.non_orthogonality_deg[own] = std::max(q.non_orthogonality_deg[own], angle);
      q.non_orthogonality_deg[nei] = std::max(q.non_orthogonality_deg[nei], angle);
    } else {
      const Eigen::Vector3d n = area / (area.norm() + kRootVSmall);
      d = n * n.dot(cpf);
    }
    // Skewness as primitiveMeshTools::faceSkewness / boundaryFaceSkewness.
    const Eigen::Vector3d sv = internal ? Eigen::Vector3d(cpf - (area.dot(cpf) / (area.dot(d) + kRootVSmall)) * d)
                                        : Eigen::Vector3d(cpf - d);
    const Eigen::Vector3d sv_hat = sv / (sv.norm() + kRootVSmall);
    double fd = 0.2 * d.norm() + kRootVSmall;
    for (int v : t) fd = std::max(fd, std::abs(sv_hat.dot(m.points[v] - fc)));
    const double skew = sv.norm() / fd;
    q.max_skewness = std::max(q.max_skewness, skew);
    q.skewness[own] = std::max(q.skewness[own], skew);
    if (internal) q.skewness[m.neighbour[f]] = std::max(q.skewness[m.neighbour[f]], skew);
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

std::vector<int> CellQuality::bad_cells(const QualityGate& gate, double d_ref) const {
  std::vector<int> bad;
  const double min_vol = gate.min_volume_d3 * d_ref * d_ref * d_ref;
  for (std::size_t c = 0; c < volume.size(); ++c)
    if (non_orthogonality_deg[c] > gate.max_non_orthogonality_deg || skewness[c] > gate.max_skewness ||
        aspect_ratio[c] > gate.max_aspect_ratio || volume[c] < min_vol)
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
          {"volume_m3", total_volume}};
}

}  // namespace bedforge::meshing
