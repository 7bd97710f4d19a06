#include "cases/drag_regions.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace bedforge::cases {

std::string GapBand::patch() const { return in_section ? fmt::format("particles_gap{}", number) : "particles_ends"; }
std::string GapBand::force_object() const {
  return in_section ? fmt::format("forceParticlesGap{}", number) : "forceParticlesEnds";
}

nlohmann::json GapBand::to_json() const {
  return {{"patch", patch()},
          {"in_section", in_section},
          {"gap_from_d", from_d},
          {"gap_to_d", std::isfinite(to_d) ? nlohmann::json(to_d) : nlohmann::json()},
          {"faces", faces},
          {"area_m2", area_m2},
          {"area_z_m2", area_z_m2},
          {"moment_z_m3", moment_z_m3},
          {"drag_n", drag_n},
          {"viscous_n", viscous_n},
          {"form_n", form_n}};
}

GapBand GapBand::from_json(const nlohmann::json& j) {
  GapBand b;
  b.from_d = j.at("gap_from_d").get<double>();
  b.to_d = j.at("gap_to_d").is_null() ? std::numeric_limits<double>::infinity() : j.at("gap_to_d").get<double>();
  b.faces = j.at("faces").get<long>();
  b.area_m2 = j.at("area_m2").get<double>();
  b.area_z_m2 = j.at("area_z_m2").get<double>();
  b.moment_z_m3 = j.at("moment_z_m3").get<double>();
  b.form_n = j.at("form_n").get<double>();
  b.drag_n = j.at("drag_n").get<double>();
  b.viscous_n = j.at("viscous_n").get<double>();
  b.in_section = j.at("in_section").get<bool>();
  const std::string patch = j.at("patch").get<std::string>();
  if (b.in_section) b.number = std::atoi(patch.c_str() + std::string("particles_gap").size());
  return b;
}

std::vector<double> gaps_at_particle_points(const std::vector<Eigen::Vector3d>& points, const Bed& bed, double reach) {
  const Periodicity period = bed.container->periodicity();
  double r_max = 0.0;
  for (double d : bed.diameters) r_max = std::max(r_max, 0.5 * d);
  // Cells at least as wide as the farthest sphere centre that can matter (its surface within
  // reach): a periodic axis takes a whole number of them over its period.
  const double h = reach + 2.0 * r_max;
  const std::array<double, 3> periods{period.lx, period.ly, period.lz};
  std::array<int, 3> n{};
  std::array<double, 3> width{};
  for (int a = 0; a < 3; ++a) {
    n[a] = periods[a] > 0.0 ? std::max(1, static_cast<int>(std::floor(periods[a] / h))) : 0;
    width[a] = periods[a] > 0.0 ? periods[a] / n[a] : h;
  }
  auto cell_of = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d w = period.wrapped(x);
    std::array<long, 3> c{};
    for (int a = 0; a < 3; ++a) {
      // Across x and y a period is wrapped to [-L/2, L/2), along z to [0, L).
      const double from = periods[a] > 0.0 && a < 2 ? -0.5 * periods[a] : 0.0;
      c[a] = static_cast<long>(std::floor((w[a] - from) / width[a]));
      if (n[a] > 0) c[a] = std::clamp<long>(c[a], 0, n[a] - 1);
    }
    return c;
  };
  auto key = [](const std::array<long, 3>& c) {
    return (static_cast<std::uint64_t>(c[0] + (1 << 20)) << 42) ^ (static_cast<std::uint64_t>(c[1] + (1 << 20)) << 21) ^
           static_cast<std::uint64_t>(c[2] + (1 << 20));
  };
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  for (std::size_t i = 0; i < bed.size(); ++i) grid[key(cell_of(bed.centres[i]))].push_back(static_cast<int>(i));

  std::vector<double> gaps(points.size(), reach);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d& x = points[k];
    // The spheres in the 27 cells around x (a periodic axis of fewer than 3 cells: each once).
    const std::array<long, 3> c = cell_of(x);
    double own = std::numeric_limits<double>::infinity(), nearest = own, second = own;
    std::array<std::vector<long>, 3> along;
    for (int a = 0; a < 3; ++a)
      for (long o = -1; o <= 1; ++o) {
        long i = c[a] + o;
        if (n[a] > 0) i = ((i % n[a]) + n[a]) % n[a];
        if (std::find(along[a].begin(), along[a].end(), i) == along[a].end()) along[a].push_back(i);
      }
    for (long i : along[0])
      for (long j : along[1])
        for (long l : along[2]) {
          const auto it = grid.find(key({i, j, l}));
          if (it == grid.end()) continue;
          for (int s : it->second) {
            const double to_surface = period.separation(x, bed.centres[s]).norm() - 0.5 * bed.diameters[s];
            // The sphere x lies on is the one whose surface is nearest in absolute value.
            if (std::abs(to_surface) < own) {
              second = std::min(second, nearest);
              own = std::abs(to_surface), nearest = to_surface;
            } else {
              second = std::min(second, to_surface);
            }
          }
        }
    double gap = second;
    WallContact walls[Container::kMaxWallContacts];
    const int touching = bed.container->wall_contacts(x, reach, walls);
    for (int w = 0; w < touching; ++w) gap = std::min(gap, reach - walls[w].overlap);
    gaps[k] = std::clamp(gap, 0.0, reach);
  }
  return gaps;
}

namespace {

// Face f's centre (its vertices' mean) and area vector (a fan from the first vertex: the faces
// here are triangles or the dual's flat-enough polygons; out of the owner cell, as OpenFOAM's).
template <class Mesh>
std::pair<Eigen::Vector3d, Eigen::Vector3d> centre_and_area(const Mesh& m, int f) {
  const std::vector<int> v = meshing::points_of(m, f);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), twice_area = Eigen::Vector3d::Zero();
  for (int p : v) centre += m.points[p] / static_cast<double>(v.size());
  for (std::size_t k = 1; k + 1 < v.size(); ++k)
    twice_area += (m.points[v[k]] - m.points[v[0]]).cross(m.points[v[k + 1]] - m.points[v[0]]);
  return {centre, 0.5 * twice_area};
}

// The faces of `m` in the order `order` (a permutation of all face labels; owners follow).
void reorder_faces(meshing::PolyMesh& m, const std::vector<int>& order) {
  std::vector<meshing::Face> faces(order.size());
  std::vector<int> owner(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) faces[k] = m.faces[order[k]], owner[k] = m.owner[order[k]];
  m.faces = std::move(faces);
  m.owner = std::move(owner);
}
void reorder_faces(meshing::PolyhedralMesh& m, const std::vector<int>& order) {
  meshing::Polygons faces;
  std::vector<int> owner(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) faces.push_back(m.faces[order[k]]), owner[k] = m.owner[order[k]];
  m.faces = std::move(faces);
  m.owner = std::move(owner);
}

template <class Mesh>
std::vector<GapBand> split(Mesh& m, const Bed& bed, double d_ref, const std::vector<double>& edges_d, double z_low,
                           double z_high) {
  const auto at = std::find_if(m.patches.begin(), m.patches.end(), [](const auto& p) { return p.name == "particles"; });
  if (at == m.patches.end()) return {};
  const meshing::PolyMesh::Patch particles = *at;
  std::vector<Eigen::Vector3d> centres(particles.size);
  std::vector<Eigen::Vector3d> areas(particles.size);
  for (int k = 0; k < particles.size; ++k) std::tie(centres[k], areas[k]) = centre_and_area(m, particles.start + k);
  const double reach = 2.0 * edges_d.back() * d_ref;  // beyond the last edge the gap's value does not matter
  const std::vector<double> gaps = gaps_at_particle_points(centres, bed, reach);
  std::vector<GapBand> bands(edges_d.size() + 2);
  std::vector<int> band_of(particles.size);
  for (std::size_t b = 0; b < bands.size(); ++b) {
    bands[b].number = static_cast<int>(b);
    bands[b].from_d = b == 0 || b > edges_d.size() ? 0.0 : edges_d[b - 1];
    bands[b].to_d = b < edges_d.size() ? edges_d[b] : std::numeric_limits<double>::infinity();
    bands[b].in_section = b <= edges_d.size();
  }
  for (int k = 0; k < particles.size; ++k) {
    const double g = gaps[k] / d_ref;
    band_of[k] = centres[k].z() < z_low || centres[k].z() > z_high
                     ? static_cast<int>(edges_d.size()) + 1
                     : static_cast<int>(std::upper_bound(edges_d.begin(), edges_d.end(), g) - edges_d.begin());
    bands[band_of[k]].faces += 1;
    bands[band_of[k]].area_m2 += areas[k].norm();
    bands[band_of[k]].area_z_m2 += areas[k].z();
    bands[band_of[k]].moment_z_m3 += centres[k].z() * areas[k].z();
  }
  // The patch's faces band by band, each band in the order it had.
  std::vector<int> order(m.owner.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin() + particles.start, order.begin() + particles.start + particles.size,
                   [&](int a, int b) { return band_of[a - particles.start] < band_of[b - particles.start]; });
  reorder_faces(m, order);
  std::vector<meshing::PolyMesh::Patch> patches(m.patches.begin(), at);
  int start = particles.start;
  for (const GapBand& b : bands) {
    meshing::PolyMesh::Patch p = particles;
    p.name = b.patch();
    p.start = start, p.size = static_cast<int>(b.faces);
    start += p.size;
    patches.push_back(p);
  }
  patches.insert(patches.end(), at + 1, m.patches.end());
  m.patches = std::move(patches);
  return bands;
}

}  // namespace

std::vector<GapBand> split_particles_by_gap(meshing::PolyMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d, double z_low, double z_high) {
  return split(mesh, bed, d_ref, edges_d, z_low, z_high);
}
std::vector<GapBand> split_particles_by_gap(meshing::PolyhedralMesh& mesh, const Bed& bed, double d_ref,
                                            const std::vector<double>& edges_d, double z_low, double z_high) {
  return split(mesh, bed, d_ref, edges_d, z_low, z_high);
}

}  // namespace bedforge::cases
