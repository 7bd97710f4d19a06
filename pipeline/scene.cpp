#include "pipeline/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/bed_io.hpp"
#include "core/error.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "meshing/surface/clip_planes.hpp"
#include "meshing/surface/periodic_box.hpp"
#include "meshing/surface/periodic_cut.hpp"
#ifdef BEDFORGE_HAVE_VOLUME_MESH
#include "pipeline/convergence_study.hpp"
#endif
#endif

namespace bedforge::pipeline {

namespace {

const std::vector<std::string> kOutputs = {"positions", "vtp", "analysis", "stl", "mesh", "case"};
const std::vector<std::string> kDefaultOutputs = {"positions", "vtp", "analysis"};

double unit_to_metres(const std::string& unit) {
  if (unit == "m") return 1.0;
  if (unit == "cm") return 1e-2;
  if (unit == "mm") return 1e-3;
  return 1e-6;  // "um"
}

// packing.soft_sphere.target_void_fraction makes the container a periodic section whose period
// the spheres set: here the period their mean volume gives, for the checks made before packing
// (the packer sets it from the spheres it draws).
void set_period_from_void_fraction(const Scene& sc, Container& c, double d_max) {
  const double eps = sc.soft_sphere.target_void_fraction;
  const std::string key = fmt::format("packing.soft_sphere.target_void_fraction = {}", eps);
  if (sc.algorithm != "soft-sphere" || sc.soft_sphere.mode != packer::SoftSphereParams::Mode::accelerated)
    throw InputError(fmt::format("{}: a target void fraction is reached by compressing a periodic section, which "
                                 "the accelerated soft-sphere packer does; allowed with packing.algorithm = "
                                 "\"soft-sphere\" and packing.soft_sphere.mode = \"accelerated\"",
                                 key));
  if (c.axial_period() > 0.0)
    throw InputError(fmt::format("{} and container.period_z_d (or _m) are both set; allowed: one of them (the target "
                                 "sets the period from the spheres)",
                                 key));
  if (sc.count == 0)
    throw InputError(fmt::format("{} with particles.count = 0; allowed: at least one sphere", key));
  c.set_axial_period(static_cast<double>(sc.count) * sc.sizes.mean_volume() / ((1.0 - eps) * c.cross_section_area()));
  if (c.axial_period() < Periodicity::kShortestInDiameters * d_max)
    throw InputError(fmt::format("{}: {} spheres give a period of {:.4g} m, shorter than 3 largest diameters ({:.4g} "
                                 "m); allowed: more spheres (particles.count) or a lower target",
                                 key, sc.count, c.axial_period(), Periodicity::kShortestInDiameters * d_max));
}

// An imported bed's periodicity is the bed's own (it was packed so): a scene's [container] gives
// the walls and keeps the file's axial period, which it may repeat but not change; sides the file
// has periodic stay periodic (a bed packed across them has no wall there).
void keep_file_periodicity(Container& c, const Container& file, const std::filesystem::path& path, double d_max) {
  const Periodicity from_file = file.periodicity(), given = c.periodicity();
  if ((from_file.lx > 0.0 && !(given.lx > 0.0)) || (from_file.ly > 0.0 && !(given.ly > 0.0)))
    throw InputError(fmt::format("[container] (or --container-diameter-m) with packing.file {}: the file's box is "
                                 "periodic across {}, where this container has walls; allowed: no [container] "
                                 "section (the file's box is the container), or a box with container.periodic_x "
                                 "and periodic_y as in the file",
                                 path.string(), from_file.lx > 0.0 && from_file.ly > 0.0 ? "x and y"
                                                : from_file.lx > 0.0                   ? "x"
                                                                                       : "y"));
  if (!(from_file.lz > 0.0)) return;
  if (c.axial_period() > 0.0 && std::abs(c.axial_period() - from_file.lz) > 1e-9 * from_file.lz)
    throw InputError(fmt::format("container.period_z: {:.6g} m, but the bed in packing.file {} repeats every {:.6g} m "
                                 "along z; allowed: no period_z (the file's is kept) or the file's",
                                 c.axial_period(), path.string(), from_file.lz));
  c.set_axial_period(from_file.lz);
  if (c.axial_period() < Periodicity::kShortestInDiameters * d_max * (1.0 - 1e-12))
    throw InputError(fmt::format("packing.file {}: its bed repeats every {:.4g} m along z, shorter than 3 largest "
                                 "diameters ({:.4g} m), which the minimum-image rule of the analysis needs; allowed: "
                                 "a bed with a longer period",
                                 path.string(), from_file.lz, Periodicity::kShortestInDiameters * d_max));
}

// What a periodic section (container.period_z) can be packed by: a packer that needs no floor (the
// accelerated soft-sphere packer, the Monte Carlo packer compressing instead of settling), or an
// imported bed.
void check_periodic_section(const Scene& sc, const toml::table& table) {
  const bool from_file = !table["container"]["period_z_m"] && !table["container"]["period_z_d"];
  const std::string key = sc.soft_sphere.target_void_fraction > 0.0 ? "packing.soft_sphere.target_void_fraction"
                          : from_file                                ? "the bed file's period along z"
                          : table["container"]["period_z_m"]          ? "container.period_z_m"
                                                                     : "container.period_z_d";
  if (sc.algorithm == "soft-sphere" && sc.soft_sphere.mode == packer::SoftSphereParams::Mode::faithful)
    throw InputError(fmt::format("{} is set, but packing.soft_sphere.mode = \"faithful\" follows Salvat et al.'s "
                                 "schedule, which settles the bed on a floor; allowed with an axial period: "
                                 "\"accelerated\"",
                                 key));

  if (sc.algorithm != "import" && sc.sizes.smallest() == sc.sizes.largest()) {
    // Equal spheres packed from random positions without friction jam at random close packing.
    const double solid = static_cast<double>(sc.count) * sc.sizes.mean_volume() /
                         (sc.container->cross_section_area() * sc.container->axial_period());
    if (solid > 0.64)
      throw InputError(fmt::format("{}: {} equal spheres in one period fill {:.3f} of it, beyond random close "
                                   "packing (0.64, Scott & Kilgour 1969), which a packing from random positions "
                                   "does not pass; allowed: a solid fraction up to 0.64 (a longer period or "
                                   "fewer spheres, particles.count)",
                                   key, sc.count, solid));
  }
}

#ifdef BEDFORGE_HAVE_VOLUME_MESH
// A bed file's own box with periodic sides is meshed only as a box periodic on every side; said
// of the file, since the scene has no container key the user could change.
void check_file_box(const Scene& sc) {
  const Periodicity per = sc.container->periodicity();
  if (!per.lateral() || meshing::is_fully_periodic_box(*sc.container)) return;
  const auto side = [](double period) { return period > 0.0 ? "periodic" : "walled"; };
  throw InputError(fmt::format("packing.file {}: its box is {} along x, {} along y and {} along z, but a box with "
                               "periodic sides is meshed only periodic on every side; allowed: a bed file periodic "
                               "along x, y and z (LAMMPS \"pp pp pp\") or walled along x and y, or outputs.files without "
                               "\"stl\", \"mesh\" and \"case\" (packing and analysis only)",
                               sc.import.file.string(), side(per.lx), side(per.ly), side(per.lz)));
}

// What a case in pieces can be given today: planes that cut no prism layers, treated contacts
// only where the walls can be ringed, and no whole surface or mesh anywhere.
void check_pieces(const Scene& sc) {
  const int n = sc.mesh.pieces;
  if (!meshing::slabs_possible(sc.mesh))
    throw InputError(fmt::format("mesh.pieces = {} with mesh.layers.count = {}: the planes between pieces would cut "
                                 "the prism layers open; allowed: 0 or 1, or mesh.pieces > 1 with mesh.layers.count = 0",
                                 n, sc.mesh.layers.count));
  if (!meshing::pieces_possible(sc.surface, *sc.container))
    throw InputError(fmt::format("mesh.pieces = {} in a box with contacts.treatment \"{}\" and "
                                 "contacts.wall_treatment \"{}\": a box's sides are not cut alike by its pieces yet; "
                                 "allowed: 0 or 1, or in a box contacts \"shrink\" or \"none\" (any treatment in a "
                                 "cylinder or annulus)",
                                 n, meshing::treatment_name(sc.surface.treatment),
                                 meshing::treatment_name(sc.surface.wall_treatment)));
  if (sc.container->axial_period() > 0.0)
    throw InputError(fmt::format("mesh.pieces = {} on a periodic section; allowed: 0 or 1", n));
  if (sc.wants("stl") || sc.wants("mesh"))
    throw InputError(fmt::format("mesh.pieces = {} with outputs.files \"stl\" or \"mesh\": in pieces there is no whole "
                                 "surface or mesh to write; allowed: outputs.files without them, or mesh.pieces = 0",
                                 n));
  if (sc.case_params.snappy)
    throw InputError(fmt::format("mesh.pieces = {} with case.mesher = \"snappy\" (or case.snappy): the pieces are "
                                 "gmsh's cells; allowed: case.mesher = \"gmsh\"",
                                 n));
  if (!sc.case_params.drag_by_gap_d.empty())
    throw InputError(fmt::format("mesh.pieces = {} with case.drag_by_gap_d: the pieces' particles are not split by "
                                 "gap; allowed: mesh.pieces = 0 or 1, or no case.drag_by_gap_d",
                                 n));
}

// What a periodic section's surface, mesh and cyclic case can be given today: spheres cut by the
// periodic planes, the bridges and caps they cross opened or cut through (enlarge only cut
// through), one piece; d_ref is the bed's reference diameter (m), the drawn sizes' or an imported bed's.
void check_periodic_surface(const Scene& sc, double d_ref) {
  if (sc.count > 0) meshing::refuse_treatments_across_periodic_planes(sc.surface);
  if (sc.surface.cut_at_periodic_planes) meshing::check_periodic_cut(*sc.container, sc.surface, d_ref);
  if (sc.surface.clip)
    throw InputError("surface.clip_window_d on a periodic section: its planes are the period's; allowed: no clip window");
  if (sc.mesh.slabs > 1)
    throw InputError(fmt::format("mesh.slabs = {} on a periodic section; allowed: 0 or 1 (one piece)", sc.mesh.slabs));
  if (sc.wants("case") && sc.case_params.snappy)
    throw InputError("case.mesher = \"snappy\" (or case.snappy) on a periodic section: its cyclic patches are made "
                     "from gmsh's cells; allowed: case.mesher = \"gmsh\"");
  // The tetrahedra's gradients are fitted over the cells sharing a vertex, a stencil OpenFOAM v1912
  // does not carry across cyclic patches ("Coupled patches with transformations not supported");
  // those it does carry biased the periodic empty tube on tetrahedra by +3.6 to +16 %, not falling
  // with the cells (docs/findings.md, 2026-12-04).
  if (sc.wants("case") && !sc.case_params.polyhedra)
    throw InputError("case.cells = \"tetrahedra\" on a periodic section: their point-neighbour gradients do not "
                     "cross OpenFOAM v1912's cyclic patches; allowed: case.cells = \"polyhedra\"");
  if (sc.mesh.layers.count > 0)
    throw InputError(fmt::format("mesh.layers.count = {} on a periodic section: layers beside the periodic planes are "
                                 "not matched yet; allowed: 0",
                                 sc.mesh.layers.count));
}
#endif

}  // namespace

bool Scene::wants(const std::string& output) const {
  return std::find(outputs.begin(), outputs.end(), output) != outputs.end();
}

nlohmann::json Scene::to_json() const {
  std::ostringstream s;
  s << toml::json_formatter{table};
  return nlohmann::json::parse(s.str());
}

namespace {

Scene read_scene_into(const toml::table& table, const std::string& source, const std::filesystem::path& base_dir,
                      SceneSchema* schema) {
  Scene sc;
  sc.table = table;
  sc.source = source;
  SceneSection root(&table, "", schema);  // top level: keys are named from their section down
  const std::vector<std::string>& sections = scene_sections();
  for (const auto& [k, v] : table) {
    const std::string key(k.str());
    if (std::find(sections.begin(), sections.end(), key) == sections.end())
      throw InputError(fmt::format("unknown section [{}] in {}; allowed: [{}]", key, source, fmt::join(sections, "], [")));
  }

  SceneSection packing = root.sub("packing");
  sc.algorithm = packing.choice("algorithm", "soft-sphere", {"soft-sphere", "monte-carlo", "import"});
  sc.seed = static_cast<std::uint64_t>(packing.integer("seed", 1, 0, std::numeric_limits<long long>::max()));
  SceneSection soft = packing.sub("soft_sphere");
  sc.soft_sphere = packer::read_soft_sphere_params(soft);
  soft.finish();
  SceneSection mc = packing.sub("monte_carlo");
  sc.monte_carlo = packer::read_monte_carlo_params(mc);
  mc.finish();

  double d_ref = 0.0, d_max = 0.0;
  SceneSection particles = root.sub("particles");
  if (sc.algorithm == "import") {
    sc.import.format = bed_file_format(packing.choice("format", "xyzd", {"xyzd", "lammps-dump", "yade"}));
    sc.import.to_metres = unit_to_metres(packing.choice("units", "m", {"m", "cm", "mm", "um"}));
    const std::vector<double> origin = packing.numbers("origin_m", Range{});
    if (!origin.empty() && origin.size() != 3)
      throw InputError(fmt::format("packing.origin_m has {} values; allowed: [x, y, z] in metres", origin.size()));
    if (origin.size() == 3) sc.import.origin_m = {origin[0], origin[1], origin[2]};
    const auto file = packing.optional_string("file");
    if (!file)
      throw InputError("packing.file is required when packing.algorithm = \"import\": a bed file (see packing.format)");
    sc.import.file = std::filesystem::path(*file).is_relative() ? base_dir / *file : std::filesystem::path(*file);
    sc.import.bed = std::make_shared<const ImportedBed>(
        read_bed_file(sc.import.file, sc.import.format, sc.import.to_metres, sc.import.origin_m));
    const std::vector<double>& diameters = sc.import.bed->bed.diameters;
    d_ref = sauter_mean(diameters);
    d_max = *std::max_element(diameters.begin(), diameters.end());
    sc.count = static_cast<long long>(diameters.size());
  } else {
    sc.count = particles.integer("count", 0, 0, 100'000'000, "none (required)");
    if (!particles.has("count"))
      throw InputError("particles.count is required: the number of spheres, an integer >= 0 (0: the empty container, "
                       "whose laminar flow has an exact answer)");
    sc.sizes = read_size_distribution(particles);
    d_ref = sc.sizes.sauter_mean();
    d_max = sc.sizes.largest();
  }
  particles.finish();
  packing.finish();

  SceneSection container = root.sub("container");
  const bool container_from_file = !table.contains("container") && sc.import.bed && sc.import.bed->bed.container;
  if (!container_from_file) {
    std::unique_ptr<Container> c = read_container(container, d_ref, d_max);
    if (sc.import.bed && sc.import.bed->bed.container)
      keep_file_periodicity(*c, *sc.import.bed->bed.container, sc.import.file, d_max);
    if (sc.soft_sphere.target_void_fraction > 0.0) set_period_from_void_fraction(sc, *c, d_max);
    sc.container = std::move(c);
  } else {
    sc.container = sc.import.bed->bed.container;
  }
  container.finish();

  SceneSection analysis = root.sub("analysis");
  sc.analysis = analysis::read_analysis_params(analysis);
  analysis.finish();

  SceneSection outputs = root.sub("outputs");
  sc.outputs = outputs.strings("files", kDefaultOutputs, kOutputs);
  outputs.finish();
  if (sc.container->axial_period() > 0.0) check_periodic_section(sc, table);
  if (sc.count == 0 && sc.wants("analysis"))
    throw InputError("outputs.files has \"analysis\", but particles.count = 0 (the empty container) has no spheres to "
                     "analyse; allowed: \"positions\", \"vtp\", \"stl\", \"mesh\", \"case\"");

  SceneSection contacts = root.sub("contacts"), surface = root.sub("surface");
#ifdef BEDFORGE_HAVE_CGAL
  sc.surface = meshing::read_surface_params(contacts, surface);
#else
  if (sc.needs_surface() || table.contains("contacts") || table.contains("surface"))
    throw InputError("this bedforge was built without CGAL, so it has no surface stage ([contacts], [surface], "
                     "outputs.files \"stl\"); install libcgal-dev and rebuild");
#endif
  contacts.finish();
  surface.finish();

  SceneSection mesh = root.sub("mesh"), case_section = root.sub("case");
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  sc.mesh = meshing::read_volume_mesh_params(mesh);
  if (sc.mesh.slabs > 1 && !meshing::slabs_possible(sc.mesh))
    throw InputError(fmt::format("mesh.slabs = {}: the planes between slabs would cut the prism layers open; allowed: "
                                 "0 or 1, or mesh.slabs > 1 with no prism layers (mesh.layers.count = {}, allowed 0)",
                                 sc.mesh.slabs, sc.mesh.layers.count));
#else
  if (sc.needs_mesh() || table.contains("mesh"))
    throw InputError("this bedforge was built without gmsh or CGAL, so it has no volume mesh stage ([mesh], "
                     "outputs.files \"mesh\" or \"case\", which needs the mesh); install libgmsh-dev and "
                     "libcgal-dev and rebuild");
#endif
  sc.case_params = cases::read_case_params(case_section);
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  if (sc.needs_surface() && container_from_file) check_file_box(sc);
  if (sc.needs_surface()) meshing::check_periodic_box(*sc.container, sc.surface);
  if (sc.needs_surface() && sc.count == 0 && meshing::is_fully_periodic_box(*sc.container))
    throw InputError("particles.count = 0 in a box periodic on every side: nothing holds the flow back (no wall, no "
                     "sphere); allowed: particles.count > 0");
  if (sc.container->axial_period() > 0.0 && sc.needs_surface()) check_periodic_surface(sc, d_ref);
  if (sc.surface.cut_at_periodic_planes && sc.container->axial_period() == 0.0)
    throw InputError("contacts.at_periodic_planes = \"cut\" without container.period_z_d (or period_z_m): there are no "
                     "periodic planes; allowed: \"open\" (the default), or a periodic section");
  if (sc.mesh.pieces > 1) check_pieces(sc);
  sc.mesh.layers = layers_for_study(sc.mesh.layers, sc.case_params.convergence);
#endif
  mesh.finish();
  case_section.finish();
  return sc;
}

}  // namespace

Scene read_scene(const toml::table& table, const std::string& source, const std::filesystem::path& base_dir) {
  return read_scene_into(table, source, base_dir, nullptr);
}

const std::vector<std::string>& scene_sections() {
  static const std::vector<std::string> sections = {"container", "particles", "packing", "analysis", "contacts",
                                                    "surface",   "mesh",      "case",    "outputs"};
  return sections;
}

SceneSchema scene_schema() {
  // Scenes that between them take every branch of the readers: each container type, an import
  // (which stops at its missing file after its own keys are recorded), each kind of size
  // distribution and a Monte Carlo mixture.
  SceneSchema schema;
  const char* scenes[] = {"container = {diameter_d = 5.0}\nparticles = {count = 1}",
                          ("container = {type = \"annulus\", diameter_d = 5.0, inner_diameter_d = 2.0}\n"
                           "particles = {count = 1}"),
                          "container = {type = \"box\", size_x_d = 5.0, size_y_d = 5.0}\nparticles = {count = 1}",
                          "packing = {algorithm = \"import\"}",
                          ("container = {diameter_d = 5.0}\nparticles = {count = 1, distribution = \"discrete\", "
                           "diameters_m = [0.001, 0.002], number_fractions = [0.5, 0.5]}\n"
                           "packing = {algorithm = \"monte-carlo\", monte_carlo = {particle_densities = [1000.0, 2000.0]}}"),
                          ("container = {diameter_d = 5.0}\nparticles = {count = 1, distribution = \"discrete\", "
                           "diameters_m = [0.001, 0.002], volume_fractions = [0.5, 0.5]}"),
                          ("container = {diameter_d = 5.0}\nparticles = {count = 1, distribution = \"normal\", "
                           "mean_m = 0.001, std_m = 0.0001}")};
  for (const char* text : scenes) {
    try {
      read_scene_into(toml::parse(text), "schema", {}, &schema);
    } catch (const InputError&) {
      // the import scene names no file: its keys are recorded by then
    }
  }
  return schema;
}

#ifdef BEDFORGE_HAVE_CGAL
cases::TreatedSolid treated_solid(const meshing::SurfaceParams& surface, const Bed& bed) {
  return {surface.sphere_scale(), surface.solid_change(bed.container->periodicity().any())};
}
#endif

Scene read_scene_file(const std::filesystem::path& path) {
  return read_scene(parse_scene_text(read_file(path), path.string()), path.string(), path.parent_path());
}

toml::table& table_for_override(toml::table& table, const std::string& dotted, std::string& leaf) {
  toml::table* t = &table;
  std::string rest = dotted;
  for (std::size_t dot; (dot = rest.find('.')) != std::string::npos;) {
    const std::string part = rest.substr(0, dot);
    if (!t->contains(part) || !(*t)[part].is_table()) t->insert_or_assign(part, toml::table{});
    t = (*t)[part].as_table();
    rest = rest.substr(dot + 1);
  }
  if (rest.size() > 2 && (rest.ends_with("_m") || rest.ends_with("_d")))
    t->erase(rest.substr(0, rest.size() - 1) + (rest.back() == 'm' ? "d" : "m"));
  leaf = rest;
  return *t;
}

void apply_overrides(toml::table& table, const std::vector<Override>& overrides) {
  auto given = [&](const std::string& key) {
    return std::any_of(overrides.begin(), overrides.end(), [&](const Override& o) { return o.key == key; });
  };
  for (const Override& o : overrides) {
    std::visit(
        [&](const auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, std::vector<double>>) {
            toml::array a;
            for (double x : v) a.push_back(x);
            override_key(table, o.key, std::move(a));
          } else {
            override_key(table, o.key, v);
          }
        },
        o.value);
  }
  if (given("surface.clip_window_d"))
    if (auto* s = table["surface"].as_table())
      for (const char* key : {"inlet_length_d", "outlet_length_d"})
        if (!given(std::string("surface.") + key)) s->erase(key);
}

std::string scene_to_toml(const toml::table& table) {
  std::ostringstream s;
  s << table;
  return s.str() + "\n";
}

}  // namespace bedforge::pipeline
