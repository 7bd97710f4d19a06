#include "meshing/volume/volume_mesh.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <random>
#include <thread>

#include <unistd.h>

#include "core/error.hpp"
#include "core/stage_meter.hpp"
#include "meshing/surface/defect_locations.hpp"
#include "meshing/volume/gmsh_model.hpp"

namespace bedforge::meshing {

const char* algorithm_name(VolumeMeshParams::Algorithm a) {
  return a == VolumeMeshParams::Algorithm::hxt ? "hxt" : "delaunay";
}

VolumeMeshParams read_volume_mesh_params(SceneSection& s) {
  VolumeMeshParams p;
  p.algorithm = s.choice("algorithm", "hxt", {"hxt", "delaunay"}) == "hxt" ? VolumeMeshParams::Algorithm::hxt
                                                                          : VolumeMeshParams::Algorithm::delaunay;
  p.fallback = s.boolean("fallback", p.fallback);
  p.max_size_d = s.number("max_size_d", p.max_size_d, Range::closed(0.01, 10.0));
  p.optimize = s.boolean("optimize", p.optimize);
  p.max_optimize_passes = static_cast<int>(s.integer("max_optimize_passes", p.max_optimize_passes, 1, 20));
  p.threads = static_cast<int>(s.integer("threads", p.threads, 0, 1024));
  p.slabs = static_cast<int>(s.integer("slabs", p.slabs, 0, 64));
  p.pieces = static_cast<int>(s.integer("pieces", p.pieces, 0, 4096));
  SceneSection g = s.sub("gate");
  p.gate.max_non_orthogonality_deg =
      g.number("max_non_orthogonality_deg", p.gate.max_non_orthogonality_deg, Range::open(0.0, 90.0));
  p.gate.max_skewness = g.number("max_skewness", p.gate.max_skewness, Range::positive());
  p.gate.max_aspect_ratio = g.number("max_aspect_ratio", p.gate.max_aspect_ratio, Range{1.0, 1e12, false, false});
  p.gate.min_volume_d3 = g.number("min_volume_d3", p.gate.min_volume_d3, Range::positive());
  g.finish();
  SceneSection layers = s.sub("layers");
  p.layers = read_prism_layer_params(layers);
  return p;
}

nlohmann::json to_json(const VolumeMeshParams& p) {
  return {{"algorithm", algorithm_name(p.algorithm)},
          {"fallback", p.fallback},
          {"max_size_d", p.max_size_d},
          {"optimize", p.optimize},
          {"max_optimize_passes", p.max_optimize_passes},
          {"threads", p.threads},
          {"slabs", p.slabs},
          {"pieces", p.pieces},
          {"gate",
           {{"max_non_orthogonality_deg", p.gate.max_non_orthogonality_deg},
            {"max_skewness", p.gate.max_skewness},
            {"max_aspect_ratio", p.gate.max_aspect_ratio},
            {"min_volume_d3", p.gate.min_volume_d3}}},
          {"layers", to_json(p.layers)}};
}

namespace {

// Components of the surface joined through shared vertices: the container (with whatever
// touches it) and one shell per free particle or cluster.
std::vector<int> shells(const TriangleMesh& s) {
  std::vector<int> parent(s.points.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& t : s.triangles)
    for (int k = 1; k < 3; ++k) parent[find(t[k])] = find(t[0]);
  std::vector<int> shell(s.triangles.size());
  std::map<int, int> number;
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    shell[t] = number.emplace(find(s.triangles[t][0]), static_cast<int>(number.size())).first->second;
  return shell;
}

// The discrete surfaces (one per shell and patch, so that HXT sees each closed shell on its own),
// their physical groups, and the fluid volume bounded by them; returns the volume's tag.
int load_surface(const TriangleMesh& s) {
  const std::vector<int> shell = shells(s);
  const int n_patches = static_cast<int>(s.patches.size());
  const int inlet = static_cast<int>(std::find(s.patches.begin(), s.patches.end(), "inlet") - s.patches.begin());
  int outer = -1;
  for (std::size_t t = 0; t < s.triangles.size() && outer < 0; ++t)
    if (s.patch[t] == inlet) outer = shell[t];
  if (outer < 0) throw InputError("volume mesh: the surface has no `inlet` patch");

  std::map<std::pair<int, int>, std::vector<std::size_t>> groups;  // (shell, patch) -> triangles
  for (std::size_t t = 0; t < s.triangles.size(); ++t) groups[{shell[t], s.patch[t]}].push_back(t);
  // The surfaces reach gmsh as one .msh file, read in a single pass: through the API every call
  // that adds elements rebuilds gmsh's node cache, O(surfaces x nodes), 51 s for the 4001 shells
  // of a = 10, N = 4000. Tags: surface k + 1 is the k-th group; node v + 1 is point v and
  // belongs to the first surface that uses it; triangle t + 1 is triangle t.
  std::vector<int> node_entity(s.points.size(), 0);
  std::map<int, std::vector<int>> shell_surfaces;
  std::vector<std::vector<int>> patch_surfaces(n_patches);
  int tag = 0;
  for (const auto& [key, tris] : groups) {
    ++tag;
    shell_surfaces[key.first].push_back(tag);
    patch_surfaces[key.second].push_back(tag);
    for (std::size_t t : tris)
      for (int v : s.triangles[t])
        if (node_entity[v] == 0) node_entity[v] = tag;
  }
  std::vector<std::vector<int>> entity_nodes(groups.size() + 1);
  for (std::size_t v = 0; v < s.points.size(); ++v)
    if (node_entity[v] != 0) entity_nodes[node_entity[v]].push_back(static_cast<int>(v));
  fmt::memory_buffer msh;
  auto out = std::back_inserter(msh);
  fmt::format_to(out, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 {} 0\n", groups.size());
  for (std::size_t e = 1; e <= groups.size(); ++e) fmt::format_to(out, "{} 0 0 0 0 0 0 0 0\n", e);
  std::size_t used = 0;
  for (const auto& nodes : entity_nodes) used += nodes.size();
  fmt::format_to(out, "$EndEntities\n$Nodes\n{} {} 1 {}\n", groups.size(), used, s.points.size());
  for (std::size_t e = 1; e <= groups.size(); ++e) {
    fmt::format_to(out, "2 {} 0 {}\n", e, entity_nodes[e].size());
    for (int v : entity_nodes[e]) fmt::format_to(out, "{}\n", v + 1);
    for (int v : entity_nodes[e]) fmt::format_to(out, "{:.17g} {:.17g} {:.17g}\n", s.points[v].x(), s.points[v].y(), s.points[v].z());
  }
  fmt::format_to(out, "$EndNodes\n$Elements\n{} {} 1 {}\n", groups.size(), s.triangles.size(), s.triangles.size());
  tag = 0;
  for (const auto& [key, tris] : groups) {
    fmt::format_to(out, "2 {} 2 {}\n", ++tag, tris.size());
    for (std::size_t t : tris)
      fmt::format_to(out, "{} {} {} {}\n", t + 1, s.triangles[t][0] + 1, s.triangles[t][1] + 1, s.triangles[t][2] + 1);
  }
  fmt::format_to(out, "$EndElements\n");
  node_entity = {}, entity_nodes = {}, groups = {};
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     fmt::format("bedforge-surface-{}-{:x}.msh", ::getpid(), std::random_device()());
  {
    std::ofstream file(path, std::ios::binary);
    file.write(msh.data(), static_cast<std::streamsize>(msh.size()));
    if (!file) throw std::runtime_error(fmt::format("volume mesh: cannot write {}", path.string()));
  }
  msh = fmt::memory_buffer();  // the text is in the file now
  try {
    gmsh::merge(path.string());
  } catch (...) {
    std::filesystem::remove(path);
    throw;
  }
  std::filesystem::remove(path);
  // The outer shell first: gmsh takes the first loop as the volume's outside.
  std::vector<int> loops{gmsh::model::geo::addSurfaceLoop(shell_surfaces[outer])};
  for (const auto& [sh, tags] : shell_surfaces)
    if (sh != outer) loops.push_back(gmsh::model::geo::addSurfaceLoop(tags));
  const int volume = gmsh::model::geo::addVolume(loops);
  gmsh::model::geo::synchronize();
  for (int p = 0; p < n_patches; ++p) {
    if (patch_surfaces[p].empty()) continue;
    const int group = gmsh::model::addPhysicalGroup(2, patch_surfaces[p]);
    gmsh::model::setPhysicalName(2, group, s.patches[p]);
  }
  const int fluid = gmsh::model::addPhysicalGroup(3, {volume});
  gmsh::model::setPhysicalName(3, fluid, "fluid");
  return volume;
}

// gmsh's element types of the cells a mesh can hold, with their numbers of points.
// The physical group of that dimension and name, or -1.
int physical_group(int dim, const std::string& name) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, dim);
  for (const auto& [d, tag] : groups) {
    std::string n;
    gmsh::model::getPhysicalName(d, tag, n);
    if (n == name) return tag;
  }
  return -1;
}

// The prism layers into the model after the tetrahedra have filled the space above them: their
// points below the tops (new nodes; the tops are the surface's nodes, tag = index + 1), their
// cells (a discrete volume joining `fluid`), and the particle triangles at their feet (a
// discrete surface that becomes the `particles` group; the tops are now inside the fluid).
void insert_layers(const PrismLayers& layers) {
  const std::size_t n_top = layers.top.points.size();
  {
    std::vector<std::size_t> triangle_tags, triangle_nodes;
    gmsh::model::mesh::getElementsByType(2, triangle_tags, triangle_nodes);
    if (triangle_tags.size() != layers.top.triangles.size())
      throw std::runtime_error(fmt::format("the tetrahedra changed the surface ({} triangles, {} given), so the prism "
                                           "layers cannot be joined to them",
                                           triangle_tags.size(), layers.top.triangles.size()));
  }
  std::vector<std::size_t> tags;
  std::vector<double> xyz, uvw;
  gmsh::model::mesh::getNodes(tags, xyz, uvw, -1, -1, false, false);
  std::size_t checked = 0, next = 0;
  for (std::size_t k = 0; k < tags.size(); ++k) {
    next = std::max(next, tags[k] + 1);
    if (tags[k] < 1 || tags[k] > n_top) continue;
    const Eigen::Vector3d& p = layers.top.points[tags[k] - 1];
    if (p != Eigen::Vector3d(xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]))
      throw std::runtime_error(fmt::format(
          "volume mesh: gmsh renumbered the surface nodes (node {} is at ({:.9g}, {:.9g}, {:.9g}) m, the layers' top "
          "point {} at ({:.9g}, {:.9g}, {:.9g}) m); the prism layers cannot be joined",
          tags[k], xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2], tags[k] - 1, p.x(), p.y(), p.z()));
    ++checked;
  }
  if (checked != n_top) throw std::runtime_error("volume mesh: gmsh dropped surface nodes; the prism layers cannot be joined");
  auto tag_of = [&](int i) {
    return static_cast<std::size_t>(i) < n_top ? static_cast<std::size_t>(i) + 1 : next + (static_cast<std::size_t>(i) - n_top);
  };

  const int volume = gmsh::model::addDiscreteEntity(3);
  std::vector<std::size_t> new_tags;
  std::vector<double> coords;
  for (std::size_t i = 0; i < layers.below.size(); ++i) {
    new_tags.push_back(next + i);
    coords.insert(coords.end(), {layers.below[i].x(), layers.below[i].y(), layers.below[i].z()});
  }
  gmsh::model::mesh::addNodes(3, volume, new_tags, coords);
  for (const auto& [type, points] : kCellTypes) {
    std::vector<std::size_t> nodes;
    for (const VolumeCell& c : layers.cells)
      if (c.n == points)
        for (int k = 0; k < c.n; ++k) nodes.push_back(tag_of(c.v[k]));
    if (!nodes.empty()) gmsh::model::mesh::addElementsByType(volume, type, {}, nodes);
  }
  const int feet = gmsh::model::addDiscreteEntity(2);
  std::vector<std::size_t> nodes;
  for (const Face& f : layers.particle_faces)
    for (int v : f) nodes.push_back(tag_of(v));
  gmsh::model::mesh::addElementsByType(feet, 2, {}, nodes);

  // The groups: `particles` is now the feet, `fluid` the tetrahedra and the layers.
  const int particles = physical_group(2, "particles"), fluid = physical_group(3, "fluid");
  std::vector<int> fluid_entities;
  gmsh::model::getEntitiesForPhysicalGroup(3, fluid, fluid_entities);
  fluid_entities.push_back(volume);
  gmsh::model::removePhysicalGroups({{2, particles}, {3, fluid}});
  gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, {feet}), "particles");
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, fluid_entities), "fluid");
}

}  // namespace

// Peak bytes per cell of a retry whose algorithm has not run on this surface yet: gmsh's
// Delaunay took 1378 (a piece of a = 14, N = 1e4, bridges: 7.9 GB after 5.7 M cells), HXT's own
// optimisation on surfaces with facets to recover 1360 (a = 10, N = 4000, enlarge: 14.2 GB,
// 10.4 M cells) and 1230 (a = 5, N = 300, enlarge); 1500 leaves a margin.
constexpr double kRetryBytesPerCell = 1500.0;
// HXT's own optimisation after HXT without it took 0.95-1.12 times the memory per cell the
// first attempt grew by (2026-11-30, docs/findings.md: 178 against 173 bytes per cell on a
// piece of a = 8, N = 1500 with no facet to recover, 1145-1239 against 1106-1199 with 631; 203
// against 196 on a piece of the 1e4 bed), so the first attempt's own growth, with this margin,
// sizes it: the constant above, from surfaces with facets to recover, skipped retries that fit.
constexpr double kSameAlgorithmMargin = 1.25;

VolumeMesh build_volume_mesh(const TriangleMesh& surface, const Bed& bed, double d_ref, const VolumeMeshParams& p,
                             const std::filesystem::path& msh_path, const std::filesystem::path& bad_cells_path,
                             Progress& progress, bool release_memory) {
  auto release = [release_memory] {
    if (release_memory) release_free_memory();
  };
  using Algorithm = VolumeMeshParams::Algorithm;
  // HXT's own optimisation (in gmsh 4.8 it runs only inside generate, not through optimize)
  // takes about five times gmsh's pass, so it is the retry, not the first try.
  struct Attempt {
    Algorithm algorithm;
    bool hxt_optimiser;
  };
  std::vector<Attempt> tries;
  auto add = [&](Algorithm a) {
    tries.push_back({a, false});
    if (a == Algorithm::hxt && p.optimize) tries.push_back({a, true});
  };
  add(p.algorithm);
  if (p.fallback) add(p.algorithm == Algorithm::hxt ? Algorithm::delaunay : Algorithm::hxt);
  // The prism layers do not depend on the algorithm: built once, the tetrahedra fill what is
  // left above them.
  std::optional<PrismLayers> layers;
  if (p.layers.count > 0) {
    progress.update(fmt::format("prism layers: {} on the particles", p.layers.count));
    layers = build_prism_layers(surface, d_ref, p.layers);
  }
  const TriangleMesh& boundary = layers ? layers->top : surface;
  nlohmann::json attempts = nlohmann::json::array();
  std::string failure;  // one sentence per attempt
  // The last attempt that gave cells: its algorithm, cells and the memory it grew by per cell
  // (NaN where unmeasured), to size a retry before it starts.
  struct Previous {
    Algorithm algorithm;
    double cells = 0.0, bytes_per_cell = std::nan("");
  };
  std::optional<Previous> previous;
  for (std::size_t attempt_index = 0; attempt_index < tries.size(); ++attempt_index) {
    const auto [algorithm, hxt_optimiser] = tries[attempt_index];
    const auto t0 = std::chrono::steady_clock::now();
    const std::string name =
        fmt::format("{}{}", algorithm_name(algorithm), hxt_optimiser ? " (its own optimiser)" : "");
    // What every entry of the report's attempts starts with.
    const nlohmann::json tried = {{"algorithm", algorithm_name(algorithm)},
                                  {"optimiser", hxt_optimiser ? "hxt" : "gmsh"}};
    auto record = [&](const char* key, const std::string& why) {
      nlohmann::json entry = tried;
      entry[key] = why;
      attempts.push_back(entry);
    };
    if (attempt_index > 0) {
      // A retry is skipped, not crashed, when it will not fit: about three cells per surface
      // triangle when no attempt before it gave cells (the first may have failed or given an
      // invalid mesh, as gmsh's threaded optimiser now and then does).
      const double cells = previous ? previous->cells : 3.0 * static_cast<double>(boundary.triangles.size());
      const bool measured = previous && previous->algorithm == algorithm && !std::isnan(previous->bytes_per_cell);
      const double need = (measured ? kSameAlgorithmMargin * previous->bytes_per_cell : kRetryBytesPerCell) * cells;
      const double available = available_memory_bytes();
      if (need > available) {
        const std::string why = fmt::format("it would need about {:.1f} GB and {:.1f} GB are available", need / 1e9,
                                            available / 1e9);
        record("skipped", why);
        failure += fmt::format("{} skipped: {}. ", name, why);
        continue;
      }
    }
    progress.update(fmt::format("{}: loading {} surface triangles", name, boundary.triangles.size()));
    const double resident_before = resident_memory_bytes();
    GmshSession session;
    auto failed = [&](const std::string& why) {
      record("error", why);
      failure += fmt::format("{} failed: {}. ", name, why);
    };
    int tetrahedra = 0;
    try {
      gmsh::model::add("bedforge");
      tetrahedra = load_surface(boundary);
      gmsh::option::setNumber("Mesh.Algorithm3D", algorithm == Algorithm::hxt ? 10 : 1);
      // The layers join the surface's nodes by their tags (index + 1), which gmsh's renumbering
      // after meshing shuffled on issue 57's bed at a 0.28 d edge (docs/findings.md, 2026-12-07).
      gmsh::option::setNumber("Mesh.Renumber", layers ? 0 : 1);
      // HXT's optimisation on two threads once left a boundary face that is no surface triangle
      // (a = 5, N = 300, enlarge); on one thread it did not.
      const int threads =
          p.threads > 0 ? p.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
      gmsh::option::setNumber("General.NumThreads", hxt_optimiser ? 1 : threads);
      gmsh::option::setNumber("Mesh.MeshSizeMax", p.max_size_d * d_ref);
      // gmsh's optimiser runs below, pass by pass, each pass measured; HXT's own inside generate.
      gmsh::option::setNumber("Mesh.Optimize", hxt_optimiser ? 1 : 0);
      progress.update(fmt::format("{}: tetrahedra", name));
      gmsh::model::mesh::generate(3);
      if (layers) insert_layers(*layers);
    } catch (const std::string& e) {  // gmsh's API throws its last error message
      failed(e);
      continue;
    } catch (const std::runtime_error& e) {  // the layers could not be joined
      failed(e.what());
      continue;
    }
    const double generated_at = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // The quality after generation and after each pass of gmsh's optimiser: the first pass
    // always (when `optimize`), more only while cells fail the gate. This is the stage's
    // convergence history, quality against time.
    VolumeMesh out;
    std::vector<int> bad;
    nlohmann::json history = nlohmann::json::array();
    std::string broken;
    for (int pass = 0;; ++pass) {
      try {
        if (pass > 0) {
          out = VolumeMesh();  // the pass remakes them; both at once would double the peak
          release();
          progress.update(fmt::format("{}: optimiser pass {} ({} cells fail the gate)", name, pass, bad.size()));
          gmsh::model::mesh::optimize("", true, 1, {{3, tetrahedra}});  // the layers are left as built
        }
        progress.update(fmt::format("{}: checking cells", name));
        release();  // what gmsh's tetrahedra or optimiser freed
        out.mesh = extract_poly_mesh();
        release();  // the extraction's face table
      } catch (const std::string& e) {
        broken = e;
      } catch (const std::exception& e) {
        broken = e.what();
      }
      if (!broken.empty()) break;
      out.quality = cell_quality(out.mesh);
      release();
      bad = out.quality.bad_cells(p.gate, d_ref);
      history.push_back({{"pass", pass},
                         {"time_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()},
                         {"max_non_orthogonality_deg", out.quality.max_non_orthogonality_deg},
                         {"max_skewness", out.quality.max_skewness},
                         {"max_aspect_ratio", out.quality.max_aspect_ratio},
                         {"cells_failing_gate", bad.size()}});
      const int passes = p.optimize ? p.max_optimize_passes : 0;
      // After HXT's own optimisation gmsh's pass is needed only for what it left.
      if (pass >= passes || (bad.empty() && (pass >= 1 || hxt_optimiser))) break;
    }
    if (!broken.empty()) {
      record("error", broken);
      failure += fmt::format("{} gave an invalid mesh: {}. ", name, broken);
      continue;
    }
    // What the attempt grew the process by, at most: the peak may be an earlier stage's.
    const double grown = peak_resident_memory_bytes() - resident_before;
    previous = Previous{algorithm, static_cast<double>(out.mesh.cells), grown / static_cast<double>(out.mesh.cells)};
    nlohmann::json attempt = tried;
    attempt.update({{"cells", out.mesh.cells},
                    {"memory_grown_mb", std::isnan(grown) ? nlohmann::json() : nlohmann::json(grown / 1048576.0)},
                    {"time_generate_s", generated_at},
                    {"optimiser_passes", history.size() - 1},
                    {"history", history},
                    {"quality", out.quality.to_json(d_ref)},
                    {"cells_failing_gate", bad.size()}});
    attempts.push_back(attempt);
    if (bad.empty()) {
      // An earlier attempt's bad cells, or an earlier run's, no longer describe the mesh written.
      if (!bad_cells_path.empty()) std::filesystem::remove(bad_cells_path);
      if (!msh_path.empty()) {
        try {
          gmsh::option::setNumber("Mesh.Binary", 1);
          gmsh::write(msh_path.string());
        } catch (const std::string& e) {
          throw std::runtime_error(fmt::format("gmsh cannot write {}: {}", msh_path.string(), e));
        }
      }
      out.report = attempt;
      out.report["attempts"] = attempts;
      if (layers) out.report["layers"] = layers->report;
      return out;
    }
    // Say where the bad cells are: the nearest particle surface to each.
    const DefectLocations where = locate_bad_cells(bed, out.mesh, out.quality, bad, bad_cells_path);
    attempts.back()["cells_failing_near"] = where.summary;  // kept when a later attempt passes
    failure += fmt::format("{}: {} of {} cells fail the gate (max non-orthogonality {:.1f} deg, limit {}; max skewness "
                          "{:.2f}, limit {}; max aspect ratio {:.0f}, limit {}; min volume {:.2e} d^3, limit {:.0e}), "
                          "most near {}; cells written to {}",
                          name, bad.size(), out.mesh.cells, out.quality.max_non_orthogonality_deg,
                          p.gate.max_non_orthogonality_deg, out.quality.max_skewness, p.gate.max_skewness,
                          out.quality.max_aspect_ratio, p.gate.max_aspect_ratio,
                          out.quality.min_volume / (d_ref * d_ref * d_ref), p.gate.min_volume_d3, where.summary,
                          bad_cells_path.string());
    failure += ". ";
  }
  throw ConvergenceError("volume mesh: no algorithm passed the quality gate. " + failure +
                           "Refine the surface near contacts ([surface] contact_edge_length_d), widen the gaps "
                           "([contacts]) or relax [mesh.gate]");
}

}  // namespace bedforge::meshing
