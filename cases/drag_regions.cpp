#include "cases/drag_regions.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/sphere_grid.hpp"

namespace bedforge::cases {

std::string GapBand::patch() const { return in_section ? fmt::format("particles_gap{}", number) : "particles_ends"; }
std::string GapBand::force_object() const {
  return in_section ? fmt::format("forceParticlesGap{}", number) : "forceParticlesEnds";
}

nlohmann::json GapBand::to_json() const {
  return {{"patch", patch()},
          {"number", number},
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
  b.number = j.at("number").get<int>();
  return b;
}

nlohmann::json Drag::to_json() const {
  nlohmann::json j{{"walls_n", walls_n},
                   {"walls_viscous_n", walls_viscous_n},
                   {"particles_n", particles_n},
                   {"particles_viscous_n", particles_viscous_n},
                   {"push_inlet_outlet_n", push_inlet_outlet_n},
                   {"wall_share", wall_share()},
                   {"force_balance_relative_error", force_balance_relative_error()}};
  if (!particles_by_gap.empty()) {
    j["particles_by_gap"] = nlohmann::json::array();
    for (const GapBand& b : particles_by_gap) j["particles_by_gap"].push_back(b.to_json());
    j["walls_ends_n"] = walls_ends_n;
    j["walls_ends_viscous_n"] = walls_ends_viscous_n;
  }
  return j;
}

Drag Drag::from_json(const nlohmann::json& j) {
  Drag d;
  d.walls_n = j.at("walls_n").get<double>();
  d.walls_viscous_n = j.at("walls_viscous_n").get<double>();
  d.particles_n = j.at("particles_n").get<double>();
  d.particles_viscous_n = j.at("particles_viscous_n").get<double>();
  d.push_inlet_outlet_n = j.at("push_inlet_outlet_n").get<double>();
  if (j.contains("particles_by_gap")) {
    for (const auto& b : j["particles_by_gap"]) d.particles_by_gap.push_back(GapBand::from_json(b));
    d.walls_ends_n = j.at("walls_ends_n").get<double>();
    d.walls_ends_viscous_n = j.at("walls_ends_viscous_n").get<double>();
  }
  return d;
}

std::vector<double> gaps_at_particle_points(const std::vector<Eigen::Vector3d>& points, const Bed& bed, double reach) {
  const Periodicity period = bed.container->periodicity();
  std::vector<double> radii(bed.size());
  for (std::size_t i = 0; i < bed.size(); ++i) radii[i] = 0.5 * bed.diameters[i];
  const double r_max = radii.empty() ? 0.0 : *std::max_element(radii.begin(), radii.end());
  // Cells at least as wide as the farthest sphere centre that can matter (its surface within
  // reach of a point on another sphere).
  SphereGrid grid;
  grid.build(bed.centres, radii, *bed.container, reach + 2.0 * r_max);

  std::vector<double> gaps(points.size(), reach);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d x = period.wrapped(points[k]);
    double own = std::numeric_limits<double>::infinity(), nearest = own, second = own;
    grid.for_each_run_around(x, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s) {
        const Eigen::Vector4d& q = grid.centre_and_radius(s);
        const double to_surface = period.separation(x, q.head<3>()).norm() - q.w();
        // The sphere x lies on is the one whose surface is nearest in absolute value.
        if (std::abs(to_surface) < own) {
          second = std::min(second, nearest);
          own = std::abs(to_surface), nearest = to_surface;
        } else {
          second = std::min(second, to_surface);
        }
      }
    });
    double gap = second;
    WallContact walls[Container::kMaxWallContacts];
    const int touching = bed.container->wall_contacts(points[k], reach, walls);
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

// Splits patch `at` of `m` into one patch per name of `names` (each keeping the patch's type), its
// face k going to names[band_of[k]], each part in the order its faces had; returns each part's
// faces. The other patches and the cells are not touched.
template <class Mesh>
std::vector<long> split_patch(Mesh& m, std::size_t at, const std::vector<int>& band_of,
                              const std::vector<std::string>& names) {
  const meshing::PolyMesh::Patch whole = m.patches[at];
  std::vector<long> faces(names.size(), 0);
  for (int b : band_of) ++faces[b];
  std::vector<int> order(m.owner.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin() + whole.start, order.begin() + whole.start + whole.size,
                   [&](int a, int b) { return band_of[a - whole.start] < band_of[b - whole.start]; });
  reorder_faces(m, order);
  std::vector<meshing::PolyMesh::Patch> patches(m.patches.begin(), m.patches.begin() + at);
  int start = whole.start;
  for (std::size_t b = 0; b < names.size(); ++b) {
    meshing::PolyMesh::Patch p = whole;
    p.name = names[b];
    p.start = start, p.size = static_cast<int>(faces[b]);
    start += p.size;
    patches.push_back(p);
  }
  patches.insert(patches.end(), m.patches.begin() + at + 1, m.patches.end());
  m.patches = std::move(patches);
  return faces;
}

bool beyond(const Eigen::Vector3d& centre, double z_low, double z_high) {
  return centre.z() < z_low || centre.z() > z_high;
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
  std::vector<std::string> names;
  for (std::size_t b = 0; b < bands.size(); ++b) {
    bands[b].number = static_cast<int>(b);
    bands[b].from_d = b == 0 || b > edges_d.size() ? 0.0 : edges_d[b - 1];
    bands[b].to_d = b < edges_d.size() ? edges_d[b] : std::numeric_limits<double>::infinity();
    bands[b].in_section = b <= edges_d.size();
    names.push_back(bands[b].patch());
  }
  for (int k = 0; k < particles.size; ++k) {
    const double g = gaps[k] / d_ref;
    band_of[k] = beyond(centres[k], z_low, z_high)
                     ? static_cast<int>(edges_d.size()) + 1
                     : static_cast<int>(std::upper_bound(edges_d.begin(), edges_d.end(), g) - edges_d.begin());
    bands[band_of[k]].faces += 1;
    bands[band_of[k]].area_m2 += areas[k].norm();
    bands[band_of[k]].area_z_m2 += areas[k].z();
    bands[band_of[k]].moment_z_m3 += centres[k].z() * areas[k].z();
  }
  split_patch(m, static_cast<std::size_t>(at - m.patches.begin()), band_of, names);
  return bands;
}

template <class Mesh>
long split_walls(Mesh& m, double z_low, double z_high) {
  long ends = 0;
  for (std::size_t at = 0; at < m.patches.size(); ++at) {
    const meshing::PolyMesh::Patch wall = m.patches[at];
    if (wall.type != "wall" || wall.name.starts_with("particles")) continue;
    std::vector<int> band_of(wall.size);
    for (int k = 0; k < wall.size; ++k) band_of[k] = beyond(centre_and_area(m, wall.start + k).first, z_low, z_high);
    ends += split_patch(m, at, band_of, {wall.name, wall.name + "_ends"})[1];
    ++at;  // past the ends just made
  }
  return ends;
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

long split_walls_at_section(meshing::PolyMesh& mesh, double z_low, double z_high) {
  return split_walls(mesh, z_low, z_high);
}
long split_walls_at_section(meshing::PolyhedralMesh& mesh, double z_low, double z_high) {
  return split_walls(mesh, z_low, z_high);
}

}  // namespace bedforge::cases
