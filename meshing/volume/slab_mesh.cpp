#include "meshing/volume/slab_mesh.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>

#include "core/error.hpp"
#include "core/point_key.hpp"
#include "core/stage_meter.hpp"
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/plane_cut.hpp"
#include "meshing/surface/primitives.hpp"
#include "meshing/surface/stl_io.hpp"

namespace bedforge::meshing {

namespace {

// A triangle by its sorted point indices.
std::array<int, 3> sorted_triangle(const Face& f) {
  std::array<int, 3> t{f[0], f[1], f[2]};
  std::sort(t.begin(), t.end());
  return t;
}

// The joined mesh as it grows: cells, the domain's boundary faces, and the top plane of the
// last slab added, waiting for the next slab's bottom.
struct Joined {
  std::vector<Eigen::Vector3d> points;
  std::vector<VolumeCell> cells;
  std::vector<Face> boundary;
  std::vector<int> patch;
  std::vector<std::string> names;
  std::unordered_map<PointKey, int, PointKeyHash> top_points;  // the last slab's outlet points
  std::vector<std::array<int, 3>> top_faces;                    // its outlet triangles, sorted

  int patch_index(const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return static_cast<int>(it - names.begin());
    names.push_back(name);
    return static_cast<int>(names.size()) - 1;
  }

  // Slab `m` on top of what is joined: its inlet (unless `first`) must be the last slab's
  // outlet; its outlet (unless `last`) waits for the next slab. `slab` counts from 0.
  void add(const PolyMesh& m, bool first, bool last, int slab) {
    const int inlet = patch_number(m, "inlet"), outlet = patch_number(m, "outlet");
    // The joined mesh's patches in the order of a slab's (gmsh_model's fixed order), as the
    // one-piece mesh and the .msh file read back have them.
    for (const auto& patch : m.patches) patch_index(patch.name);
    std::vector<char> on_inlet(m.points.size(), 0), on_outlet(m.points.size(), 0);
    for (const auto& [p, flags] : {std::pair{inlet, &on_inlet}, std::pair{outlet, &on_outlet}})
      for (int f = m.patches[p].start; f < m.patches[p].start + m.patches[p].size; ++f)
        for (int v : m.faces[f]) (*flags)[v] = 1;
    // Points: the inlet's are the last slab's outlet points, the rest are new.
    std::vector<int> global(m.points.size());
    std::unordered_map<PointKey, int, PointKeyHash> next_top;
    long unmatched = 0;
    Eigen::Vector3d unmatched_at = Eigen::Vector3d::Zero();
    for (std::size_t v = 0; v < m.points.size(); ++v) {
      const Eigen::Vector3d& x = m.points[v];
      const PointKey key(x);
      if (!first && on_inlet[v]) {
        const auto it = top_points.find(key);
        if (it == top_points.end()) {
          if (unmatched++ == 0) unmatched_at = x;
          global[v] = static_cast<int>(points.size());
          points.push_back(x);
        } else {
          global[v] = it->second;
        }
      } else {
        global[v] = static_cast<int>(points.size());
        points.push_back(x);
      }
      if (!last && on_outlet[v]) next_top.emplace(key, global[v]);
    }
    // Faces: the shared plane's must be the last slab's outlet, triangle for triangle.
    std::vector<std::array<int, 3>> bottom_faces, next_top_faces;
    for (std::size_t p = 0; p < m.patches.size(); ++p)
      for (int f = m.patches[p].start; f < m.patches[p].start + m.patches[p].size; ++f) {
        Face g = m.faces[f];
        for (int& v : g) v = global[v];
        if (!first && static_cast<int>(p) == inlet) {
          bottom_faces.push_back(sorted_triangle(g));
        } else if (!last && static_cast<int>(p) == outlet) {
          next_top_faces.push_back(sorted_triangle(g));
        } else {
          boundary.push_back(g);
          patch.push_back(patch_index(m.patches[p].name));
        }
      }
    if (!first) {
      std::sort(bottom_faces.begin(), bottom_faces.end());
      std::sort(top_faces.begin(), top_faces.end());
      if (unmatched > 0 || bottom_faces != top_faces)
        throw std::runtime_error(fmt::format(
            "volume mesh: slabs {} and {} do not triangulate their shared plane alike ({} of its {} points and {} of "
            "{} triangles on one side only, the first point at ({:.6g}, {:.6g}, {:.6g}) m); please report it with the "
            "bed",
            slab, slab + 1, unmatched, std::count(on_inlet.begin(), on_inlet.end(), 1), [&] {
              std::vector<std::array<int, 3>> only;
              std::set_symmetric_difference(bottom_faces.begin(), bottom_faces.end(), top_faces.begin(),
                                            top_faces.end(), std::back_inserter(only));
              return only.size();
            }(),
            top_faces.size() + bottom_faces.size(), unmatched_at.x(), unmatched_at.y(), unmatched_at.z()));
    }
    top_points = std::move(next_top);
    top_faces = std::move(next_top_faces);
    // Cells: a tetrahedron's points are those of its faces (the slabs have no prism layers).
    std::vector<VolumeCell> slab_cells = tetrahedra(m);
    for (VolumeCell& c : slab_cells)
      for (int j = 0; j < c.n; ++j) c.v[j] = global[c.v[j]];
    cells.insert(cells.end(), slab_cells.begin(), slab_cells.end());
  }
};

// The joined mesh as gmsh's MSH 2.2, binary (a third of the text's size, and no number
// formatting): the tetrahedra in physical volume `fluid`, the boundary triangles in one physical
// surface per patch; `bedforge case DIR` reads it back.
void write_msh22(const std::filesystem::path& path, const Joined& j) {
  std::ofstream out(path, std::ios::binary);
  const int n = static_cast<int>(j.names.size()), one = 1;
  auto put = [&out](const auto& value) { out.write(reinterpret_cast<const char*>(&value), sizeof value); };
  out << "$MeshFormat\n2.2 1 8\n";
  put(one);  // tells the reader the byte order
  out << "\n$EndMeshFormat\n$PhysicalNames\n" << n + 1 << "\n";
  for (int p = 0; p < n; ++p) out << "2 " << p + 1 << " \"" << j.names[p] << "\"\n";
  out << "3 " << n + 1 << " \"fluid\"\n$EndPhysicalNames\n$Nodes\n" << j.points.size() << "\n";
  for (std::size_t v = 0; v < j.points.size(); ++v) {
    put(static_cast<int>(v + 1));
    put(j.points[v]);  // three doubles
  }
  out << "\n$EndNodes\n$Elements\n" << j.boundary.size() + j.cells.size() << "\n";
  // Blocks of one element type: (type, count, tags), then each element's number, tags and nodes.
  int e = 0;
  for (std::size_t b = 0; b < j.boundary.size(); ++b) {
    put(std::array<int, 3>{2, 1, 2});
    const Face& f = j.boundary[b];
    put(std::array<int, 6>{++e, j.patch[b] + 1, j.patch[b] + 1, f[0] + 1, f[1] + 1, f[2] + 1});
  }
  put(std::array<int, 3>{4, static_cast<int>(j.cells.size()), 2});
  for (const VolumeCell& c : j.cells) put(std::array<int, 7>{++e, n + 1, n + 1, c.v[0] + 1, c.v[1] + 1, c.v[2] + 1, c.v[3] + 1});
  out << "\n$EndElements\n";
  if (!out) throw std::runtime_error(fmt::format("volume mesh: cannot write {}", path.string()));
}

// What a slab's report says of one of its plane cuts (at `plane_d`, d above the floor).
nlohmann::json cut_json(const PlaneCut& c, double plane_d) {
  nlohmann::json j = to_json(c);
  j["plane_d"] = plane_d;
  return j;
}

// Slab `k` of `slabs` from its closed surface, quietly, its failure naming it by `heights_d`
// (asked, d above the floor); the report adds those heights, the surface's triangles and the cells.
VolumeMesh mesh_slab_surface(const TriangleMesh& surface, const Bed& bed, double d_ref, const VolumeMeshParams& p,
                             const std::filesystem::path& bad_cells_path, bool release_memory, int k, int slabs,
                             const std::array<double, 2>& heights_d) {
  Progress quiet("mesh", false);
  VolumeMesh slab;
  try {
    slab = build_volume_mesh(surface, bed, d_ref, p, {}, bad_cells_path, quiet, release_memory);
  } catch (const ConvergenceError& e) {
    throw ConvergenceError(fmt::format("slab {} of {} ({:.2f}-{:.2f} d above the floor): {}", k + 1, slabs,
                                       heights_d[0], heights_d[1], e.what()));
  }
  slab.report["heights_d"] = heights_d;
  slab.report["surface_triangles"] = surface.triangles.size();
  slab.report["cells"] = slab.mesh.cells;
  return slab;
}

// The slabbed mesh between `planes` (d): each slab meshed and joined, the joined mesh checked.
VolumeMesh mesh_and_join_slabs(const Bed& bed, const SurfaceParams& surface, const TriangleMesh* whole,
                               const std::vector<double>& planes, double d_ref, const VolumeMeshParams& p,
                               const std::filesystem::path& msh_path, const std::filesystem::path& bad_cells_path,
                               Progress& progress);

}  // namespace

bool slabs_possible(const VolumeMeshParams& p) { return p.layers.count == 0; }

bool slabs_from_clip_windows(const SurfaceParams& s) {
  using T = SurfaceParams::Treatment;
  const auto alone = [](T t) { return t == T::shrink || t == T::none; };
  return alone(s.treatment) && alone(s.wall_treatment);
}

bool pieces_possible(const SurfaceParams& s, const Container& container) {
  return slabs_from_clip_windows(s) || dynamic_cast<const Box*>(&container) == nullptr;
}

bool meshes_in_slabs(const SurfaceParams& s, const VolumeMeshParams& p, const Container& container) {
  if (!slabs_possible(p) || container.axial_period() > 0.0) return false;
  return p.slabs > 1 || (p.slabs == 0 && slabs_from_clip_windows(s));
}

int slab_count(std::size_t surface_triangles, const SurfaceParams& s, const VolumeMeshParams& p,
               const Container& container) {
  if (!meshes_in_slabs(s, p, container)) return 1;
  if (p.slabs > 0) return p.slabs;
  return std::max(1, static_cast<int>(std::ceil(static_cast<double>(surface_triangles) / kSurfaceTrianglesPerSlab)));
}

FluidDomainProfile slab_profile(const Bed& bed, const SurfaceParams& s, int slabs, double volume_per_cell,
                                std::size_t spheres_per_window) {
  const double d = reference_diameter(bed), inf = std::numeric_limits<double>::infinity();
  const double span_d = (s.clip ? s.clip_top_d - s.clip_bottom_d
                                : bed_height(bed) / d + s.inlet_length_d + s.outlet_length_d);
  const int bins = std::clamp(static_cast<int>(std::ceil(span_d / 0.02)), 100 * std::max(slabs, 1), 1 << 22);
  const std::vector<double> stretches = survey_stretches(bed, spheres_per_window);
  // A clip window's planes move clear of the contacts near them, which its whole survey places;
  // a periodic section is laid out whole.
  if (stretches.size() == 2 || s.clip || bed.container->axial_period() > 0.0)
    return fluid_domain_profile(bed, s, volume_per_cell, bins);
  // Window by window on the whole domain's bins, each stretch's bins from its own window.
  const std::array<double, 2> grid{-s.inlet_length_d * d, bed_height(bed) + s.outlet_length_d * d};
  const double height = (grid[1] - grid[0]) / bins, margin = piece_margin_d(bed, s) * d;
  const std::vector<double> none(bins, 0.0);
  FluidDomainProfile out{{}, grid[0], grid[1], none, none, none, none, inf};
  for (std::size_t k = 0; k + 1 < stretches.size(); ++k) {
    const double lo = stretches[k], hi = stretches[k + 1];
    const CutWindow w = survey_window(bed, s, lo - margin, hi + margin);
    const FluidDomainProfile part = fluid_domain_profile(w.bed, w.surface, volume_per_cell, bins, grid);
    double own = 0.0, all = 0.0;  // the window's cells in its stretch, and in all
    for (int b = 0; b < bins; ++b) {
      all += part.cells[b];
      if (const double z = grid[0] + (b + 0.5) * height; !(z >= lo && z < hi)) continue;
      out.cells[b] = part.cells[b], out.fluid_m3[b] = part.fluid_m3[b], out.gap_cells[b] = part.gap_cells[b];
      out.loop_edges[b] = part.loop_edges[b];
      own += part.cells[b];
      out.size.volume_m3 += part.fluid_m3[b], out.size.gap_cells += part.gap_cells[b];
      out.size.contact_loop_edges += part.loop_edges[b];
    }
    // The thin gaps are not binned: the stretch's share as its cells'.
    out.size.thin_gap_contacts += (all > 0.0 ? own / all : 0.0) * part.size.thin_gap_contacts;
    // Each window's survey holds its spheres' wall gaps as the whole bed's does.
    out.bed_wall_gap_m = std::min(out.bed_wall_gap_m, part.bed_wall_gap_m);
  }
  return out;
}

FluidDomainSize slab_domain_size(const Bed& bed, const SurfaceParams& s, const std::vector<double>& planes, int k,
                                 double volume_per_cell) {
  const int slabs = static_cast<int>(planes.size()) + 1;
  const double d = reference_diameter(bed), margin = piece_margin_d(bed, s), inf = std::numeric_limits<double>::infinity();
  const double lo = k > 0 ? planes[k - 1] * d : -inf, hi = k + 1 < slabs ? planes[k] * d : inf;
  const CutWindow w = survey_window(bed, s, lo - margin * d, hi + margin * d);
  const FluidDomainProfile profile = slab_profile(w.bed, w.surface, 1, volume_per_cell);
  // The share of a binned quantity between the slab's planes, bins cut by a plane in proportion.
  const double height = (profile.z1 - profile.z0) / static_cast<double>(profile.cells.size());
  auto share = [&](const std::vector<double>& bins) {
    double inside = 0.0, all = 0.0;
    for (std::size_t b = 0; b < bins.size(); ++b) {
      const double z = profile.z0 + static_cast<double>(b) * height;
      inside += bins[b] * std::clamp((std::min(hi, z + height) - std::max(lo, z)) / height, 0.0, 1.0);
      all += bins[b];
    }
    return all > 0.0 ? inside / all : 0.0;
  };
  FluidDomainSize out = profile.size;
  out.volume_m3 *= share(profile.fluid_m3);
  out.gap_cells *= share(profile.gap_cells);
  out.contact_loop_edges *= share(profile.loop_edges);
  out.thin_gap_contacts *= share(profile.cells);  // not binned: as the cells are shared
  return out;
}

std::vector<double> slab_planes_d(const Bed& bed, const SurfaceParams& s, int slabs) {
  return slabs < 2 ? std::vector<double>{} : slab_planes(bed, s, slabs).planes_d;
}

SlabPlanes slab_planes(const Bed& bed, const SurfaceParams& s, int slabs) {
  const FluidDomainProfile profile = slab_profile(bed, s, slabs, 1.0);
  return {slab_planes_d(bed, s, profile, slabs), profile.bed_wall_gap_m};
}

std::vector<double> slab_planes_d(const Bed& bed, const SurfaceParams& s, const FluidDomainProfile& profile,
                                  int slabs) {
  std::vector<double> planes;
  if (slabs < 2) return planes;
  const double d = reference_diameter(bed);
  const int bins = static_cast<int>(profile.cells.size());
  std::vector<double> below(bins + 1, 0.0);  // cells below each bin's bottom
  std::partial_sum(profile.cells.begin(), profile.cells.end(), below.begin() + 1);
  const double height = (profile.z1 - profile.z0) / bins;
  const ClearHeights ends = plane_clear_heights_d(bed, s, !slabs_from_clip_windows(s));
  for (int k = 1; k < slabs; ++k) {
    // Where the cells below reach k / slabs of them, within its bin by linear interpolation.
    const double target = below.back() * k / slabs;
    const int b = std::clamp(static_cast<int>(std::upper_bound(below.begin(), below.end(), target) - below.begin()) - 1,
                             0, bins - 1);
    const double share = profile.cells[b] > 0.0 ? (target - below[b]) / profile.cells[b] : 0.0;
    const double asked = (profile.z0 + (b + std::clamp(share, 0.0, 1.0)) * height) / d;
    planes.push_back(widest_interval_middle(ends, asked, s.clip_shift_d, std::nan(""), s.clip_clearance_d));
  }
  return planes;
}

std::vector<double> moved_slab_planes_d(const Bed& bed, const SurfaceParams& s, const std::vector<double>& planes,
                                        const std::vector<int>& failed) {
  const ClearHeights ends = plane_clear_heights_d(bed, s, !slabs_from_clip_windows(s));
  const auto named = [&](int slab) { return std::find(failed.begin(), failed.end(), slab) != failed.end(); };
  std::vector<double> moved = planes;
  for (int j = 0; j < static_cast<int>(planes.size()); ++j)  // plane j lies between slabs j and j + 1
    if (failed.empty() || named(j) || named(j + 1))
      moved[j] = widest_interval_middle(ends, planes[j], s.clip_shift_d, planes[j], s.clip_clearance_d);
  return moved;
}

void throw_slabs_failed(bool cut, const std::string& key, const std::string& what) {
  if (cut) throw InputError(fmt::format("{}: {}; allowed: another value of {}, or {} = 1", key, what, key, key));
  throw ConvergenceError(what);
}

void check_given_planes_d(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int slabs,
                          const std::string& name) {
  const SurfaceParams whole = slab_surface(bed, surface, {}, 0);
  const bool increasing = std::adjacent_find(planes.begin(), planes.end(), std::greater_equal<>()) == planes.end();
  const bool inside = std::all_of(planes.begin(), planes.end(),
                                  [&](double z) { return z > whole.clip_bottom_d && z < whole.clip_top_d; });
  if (static_cast<int>(planes.size()) + 1 != slabs || !increasing || !inside)
    throw InputError(fmt::format("{} {}: allowed: {} height{} (d above the floor), increasing, between the fluid "
                                 "domain's ends {:.3f} and {:.3f} d",
                                 name, fmt::join(planes, " "), slabs - 1, slabs == 2 ? "" : "s", whole.clip_bottom_d,
                                 whole.clip_top_d));
}

SurfaceParams slab_surface(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int k) {
  const double d = reference_diameter(bed);
  const int slabs = static_cast<int>(planes.size()) + 1;
  SurfaceParams q = surface;
  q.clip = true;
  q.clip_bottom_d = k > 0 ? planes[k - 1] : surface.clip ? surface.clip_bottom_d : -surface.inlet_length_d;
  q.clip_top_d = k + 1 < slabs ? planes[k] : surface.clip ? surface.clip_top_d : bed_height(bed) / d + surface.outlet_length_d;
  return q;
}

VolumeMesh mesh_slab(const Bed& bed, const SurfaceParams& surface, const std::vector<double>& planes, int k,
                     double d_ref, const VolumeMeshParams& p, const std::filesystem::path& bad_cells_path,
                     bool release_memory) {
  const int slabs = static_cast<int>(planes.size()) + 1;
  const SurfaceParams asked = slab_surface(bed, surface, planes, k);
  // Treated contacts: the spheres within piece_margin_d of the slab, ringed at every plane
  // (window_for_cuts), their surface then cut at the slab's own planes.
  const bool cut = !slabs_from_clip_windows(surface);
  const double d = reference_diameter(bed), inf = std::numeric_limits<double>::infinity();
  const double margin = piece_margin_d(bed, surface);
  // Shrink or none: the spheres within the margin of the slab's clip window, so that its survey
  // of the contacts reads no more of the bed.
  const CutWindow window =
      cut ? window_for_cuts(bed, surface, k > 0 ? (planes[k - 1] - margin) * d : -inf,
                            k + 1 < slabs ? (planes[k] + margin) * d : inf, planes)
          : spheres_between(bed, asked, (asked.clip_bottom_d - margin) * d, (asked.clip_top_d + margin) * d);
  const Bed& window_bed = window.bed;
  const SurfaceParams& q = window.surface;
  // The slab's clip planes may find no height clear of the spheres, or cut one too close to
  // another cut: say which slab, since the scene set no clip window.
  auto cannot = [&](const std::string& what) {
    return SlabCutError(fmt::format("slab {} of {} ({:.2f}-{:.2f} d above the floor) {}: {}", k + 1, slabs,
                                    asked.clip_bottom_d, asked.clip_top_d, kSlabCutPhrase, what));
  };
  FluidSurface fs = [&] {
    try {
      return build_fluid_surface(window_bed, q);
    } catch (const InputError& e) {
      throw cannot(in_bed_numbers(window, e.what()));
    }
  }();
  nlohmann::json planes_used = {fs.report["clip"]["inlet"]["used_d"], fs.report["clip"]["outlet"]["used_d"]};
  nlohmann::json cut_report = nlohmann::json::array();
  if (cut) {
    for (const auto& [j, keep_above] : {std::pair{k - 1, true}, std::pair{k, false}}) {
      if (j < 0 || j + 1 >= slabs) continue;
      try {
        PlaneCut c = cut_by_plane(fs.fluid, round_to_ascii_stl(planes[j] * d), plane_cut_params(surface, window_bed, fs));
        cut_report.push_back(cut_json(c, planes[j]));
        fs.fluid = std::move(keep_above ? c.above : c.below);
      } catch (const CutConflict& e) {
        throw cannot(e.what());
      }
      planes_used[keep_above ? 0 : 1] = planes[j];
    }
  }
  // Only the fluid surface goes on: the window's solid and pieces would sit beside gmsh's cells.
  const TriangleMesh fluid = std::move(fs.fluid);
  fs = FluidSurface();
  if (release_memory) release_free_memory();
  VolumeMesh slab = mesh_slab_surface(fluid, bed, d_ref, p, bad_cells_path, release_memory, k, slabs,
                                      {asked.clip_bottom_d, asked.clip_top_d});
  slab.report["planes_d"] = std::move(planes_used);
  if (cut) slab.report["plane_cut"] = std::move(cut_report);
  return slab;
}

VolumeMesh build_slabbed_volume_mesh(const Bed& bed, const SurfaceParams& surface, const TriangleMesh* whole,
                                     int slabs, double d_ref, const VolumeMeshParams& p,
                                     const std::filesystem::path& msh_path,
                                     const std::filesystem::path& bad_cells_path, Progress& progress) {
  if (!pieces_possible(surface, *bed.container) && whole == nullptr)
    throw std::invalid_argument("build_slabbed_volume_mesh: treated contacts in a box need the whole surface to cut slabs from");
  // One survey of the bed for the planes and the gap every slab's window rings its walls with.
  const SlabPlanes at = slab_planes(bed, surface, slabs);
  SurfaceParams ringed = surface;
  ringed.ring_wall_gap_m = at.wall_gap_m;
  std::optional<PlanesMoved> moved;
  VolumeMesh out = attempt_with_planes_moved(
      bed, surface, at.planes_d, "mesh.slabs",
      [&](const std::vector<double>& planes) {
        return mesh_and_join_slabs(bed, ringed, whole, planes, d_ref, p, msh_path, bad_cells_path, progress);
      },
      [&moved](const PlanesMoved& m) { moved = m; });
  if (moved) out.report["planes_moved"] = {{"from_d", moved->from_d}, {"to_d", moved->to_d}, {"because", moved->because}};
  return out;
}

namespace {

VolumeMesh mesh_and_join_slabs(const Bed& bed, const SurfaceParams& surface, const TriangleMesh* whole,
                               const std::vector<double>& planes, double d_ref, const VolumeMeshParams& p,
                               const std::filesystem::path& msh_path, const std::filesystem::path& bad_cells_path,
                               Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const int slabs = static_cast<int>(planes.size()) + 1;
  // Treated contacts in a box: slabs cut from the whole surface, whose flat sides windows would
  // not cut alike (they are not ringed); elsewhere each slab from its own window, as on ranks.
  const bool from_whole = !pieces_possible(surface, *bed.container);
  const double d = reference_diameter(bed);
  TriangleMesh above;  // slabs from the whole surface: the part above the planes cut so far
  if (from_whole) above = *whole;
  // The whole surface keeps no treated radii: its cuts' faces are sized from the spheres' own.
  std::vector<double> radii(bed.size());
  for (std::size_t i = 0; i < bed.size(); ++i) radii[i] = 0.5 * bed.diameters[i];
  Joined joined;
  nlohmann::json reports = nlohmann::json::array();
  for (int k = 0; k < slabs; ++k) {
    progress.update(fmt::format("slab {} of {}: surface and cells", k + 1, slabs));
    // Memory a slab frees stays with the allocator for the next slab and the join: handing it
    // back and faulting it in again made the stage 1.7 times slower (a = 10, N = 4000).
    VolumeMesh slab;
    if (!from_whole) {
      slab = mesh_slab(bed, surface, planes, k, d_ref, p, bad_cells_path, false);
    } else {
      const SurfaceParams q = slab_surface(bed, surface, planes, k);
      TriangleMesh own = std::move(above);
      nlohmann::json cut_report = nlohmann::json::array();
      if (k + 1 < slabs) {
        try {
          PlaneCutParams cut_params = plane_cut_params(surface, d);
          cut_params.spheres = spheres_near_planes(bed.centres, radii, {planes[k] * d},
                                                   kSpheresNearPlaneReach * surface.cells_per_gap * surface.edge_length_d * d);
          cut_params.container = bed.container;
          PlaneCut c = cut_by_plane(own, planes[k] * d, cut_params);
          cut_report.push_back(cut_json(c, planes[k]));
          own = std::move(c.below), above = std::move(c.above);
        } catch (const CutConflict& e) {
          throw SlabCutError(fmt::format("the plane at {:.3f} d above the floor {}'s surface: {}", planes[k],
                                         kSlabCutPhrase, e.what()));
        }
      }
      slab = mesh_slab_surface(own, bed, d_ref, p, bad_cells_path, false, k, slabs, {q.clip_bottom_d, q.clip_top_d});
      slab.report["planes_d"] = slab.report["heights_d"];
      slab.report["plane_cut"] = std::move(cut_report);
    }
    progress.update(fmt::format("slab {} of {}: {} cells joined", k + 1, slabs, slab.mesh.cells), (k + 1.0) / slabs);
    joined.add(slab.mesh, k == 0, k + 1 == slabs, k);
    reports.push_back(std::move(slab.report));
  }
  joined.top_points = {};
  release_free_memory();  // the slabs' gmsh models: the join's arrays are of other sizes
  auto since = [&t0] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const double slabs_done = since();
  // The .msh file now, from the cells as they are, so that they need not outlive the join; it
  // is removed if the joined mesh fails the gate.
  if (!msh_path.empty()) write_msh22(msh_path, joined);
  const double written_at = since();
  progress.update(fmt::format("{} slabs joined: checking cells", slabs));
  std::vector<std::string> types;
  for (const auto& name : joined.names) types.push_back(patch_type(name));
  VolumeMesh out;
  out.mesh = poly_mesh_from_cells(std::move(joined.points), joined.cells, joined.boundary, joined.patch, joined.names,
                                  types);
  joined = Joined();
  release_free_memory();  // the join's face table
  const double joined_at = since();
  out.quality = cell_quality(out.mesh);
  const std::vector<int> bad = out.quality.bad_cells(p.gate, d_ref);
  // The slabs' algorithms and optimisers, each named once.
  auto used = [&](const char* key) {
    std::vector<std::string> names;
    for (const auto& r : reports)
      if (std::find(names.begin(), names.end(), r[key].get<std::string>()) == names.end())
        names.push_back(r[key].get<std::string>());
    return fmt::format("{}", fmt::join(names, "+"));
  };
  out.report = {{"algorithm", used("algorithm")}, {"optimiser", used("optimiser")}, {"slabs", reports}};
  out.report["cells"] = out.mesh.cells;
  out.report["quality"] = out.quality.to_json(d_ref);
  out.report["cells_failing_gate"] = bad.size();
  out.report["time_slabs_s"] = slabs_done;
  if (!msh_path.empty()) out.report["time_msh_s"] = written_at - slabs_done;
  out.report["time_join_s"] = joined_at - written_at;
  out.report["time_quality_s"] = since() - joined_at;
  if (!bad.empty()) {
    const DefectLocations where = locate_bad_cells(bed, out.mesh, out.quality, bad, bad_cells_path);
    if (!msh_path.empty()) std::filesystem::remove(msh_path);
    throw ConvergenceError(fmt::format(
        "volume mesh: every slab passed the quality gate but {} of {} cells of the joined mesh fail it (max "
        "non-orthogonality {:.1f} deg, limit {}), most near {}; cells written to {}. Mesh in one piece "
        "(mesh.slabs = 1)",
        bad.size(), out.mesh.cells, out.quality.max_non_orthogonality_deg, p.gate.max_non_orthogonality_deg,
        where.summary, bad_cells_path.string()));
  }
  release_free_memory();  // the quality measures' face geometry
  return out;
}

}  // namespace

}  // namespace bedforge::meshing
