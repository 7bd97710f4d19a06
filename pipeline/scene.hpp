#pragma once
#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

#include "analysis/bed_analysis.hpp"
#include "core/container.hpp"
#include "core/dem_import.hpp"
#include "core/size_distribution.hpp"
#include "cases/case_params.hpp"
#include "packer/monte_carlo.hpp"
#include "packer/soft_sphere.hpp"
#ifdef BEDFORGE_HAVE_CGAL
#include "meshing/surface/fluid_surface.hpp"
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
#include "meshing/volume/slab_mesh.hpp"
#include "meshing/volume/volume_mesh.hpp"
#endif

namespace bedforge::pipeline {

// A scene: what to build and which outputs to write. Sections: [container], [particles],
// [packing] (with [packing.soft_sphere] and [packing.monte_carlo]), [analysis], [contacts],
// [surface], [mesh], [case], [outputs]. Lengths are given in metres
// (keys ending in _m) or in particle diameters (keys ending in _d).
struct Scene {
  toml::table table;   // as run: the file plus command-line overrides
  std::string source;  // file name, or "command line"

  // [packing]
  std::string algorithm = "soft-sphere";  // "soft-sphere" | "monte-carlo" | "import"
  std::uint64_t seed = 1;
  packer::SoftSphereParams soft_sphere;
  packer::MonteCarloParams monte_carlo;
  // algorithm = "import": a bed file (packing.file, format, units, origin_m), read once by
  // read_scene, which needs its diameters for the container.
  struct Import {
    std::filesystem::path file;
    BedFileFormat format = BedFileFormat::xyzd;
    double to_metres = 1.0;
    Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
    std::shared_ptr<const ImportedBed> bed;
  } import;

  // [particles] (not used by "import")
  SizeDistribution sizes;
  long long count = 0;

  // [container], in metres; for "import" it may come from the bed file's header instead.
  std::shared_ptr<const Container> container;
  analysis::AnalysisParams analysis;
#ifdef BEDFORGE_HAVE_CGAL
  meshing::SurfaceParams surface;  // [contacts] and [surface]
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  meshing::VolumeMeshParams mesh;  // [mesh]
#endif
  cases::CaseParams case_params;   // [case]
  // [outputs] files: "positions" (bed.csv), "vtp" (bed.vtp), "analysis" (profiles, contacts),
  // "stl" (the fluid-domain surface and the bed solid; needs a build with CGAL), "mesh" (the
  // gmsh volume mesh fluid.msh; needs gmsh), "case" (the OpenFOAM case in case/; runs the
  // surface and mesh stages).
  std::vector<std::string> outputs;

  bool wants(const std::string& output) const;
  // Whether a stage must run: for its own output or for a later stage's.
  bool needs_surface() const { return wants("stl") || needs_mesh(); }
  bool needs_mesh() const { return wants("mesh") || wants("case"); }
  nlohmann::json to_json() const;  // the table as JSON, for headers and reports
};

// Checks and reads a whole scene; InputError names the first bad key. A relative
// `packing.file` is taken relative to `base_dir` (the scene file's folder).
Scene read_scene(const toml::table& table, const std::string& source, const std::filesystem::path& base_dir = {});
Scene read_scene_file(const std::filesystem::path& path);

#ifdef BEDFORGE_HAVE_CGAL
// What the contact treatment `surface` does to `bed`'s spheres, as its case compares them with a
// known answer (cases::set_known_answers).
cases::TreatedSolid treated_solid(const meshing::SurfaceParams& surface, const Bed& bed);
#endif

// Every key a scene can hold, with its type, range and default, as the section readers ask for
// them (for the command line's help and docs/scene_reference.md).
SceneSchema scene_schema();

// The top-level sections of a scene, in the order a scene is read.
const std::vector<std::string>& scene_sections();

// The table that holds `dotted.key` (created if missing); `leaf` receives the last part. For a
// length key (ending in _m or _d) the key in the other unit is removed, so an override wins.
toml::table& table_for_override(toml::table& table, const std::string& dotted_key, std::string& leaf);

// Sets `dotted.key` = value in a scene table (command-line overrides).
template <class T>
void override_key(toml::table& table, const std::string& dotted_key, T value) {
  std::string leaf;
  table_for_override(table, dotted_key, leaf).insert_or_assign(leaf, std::move(value));
}

// A scene key set from the command line.
struct Override {
  std::string key;  // dotted, e.g. "container.diameter_d"
  std::variant<bool, long long, double, std::string, std::vector<double>> value;
};
// Applies `overrides` in order. A clip window given without empty-section lengths replaces the
// lengths the table gives (a window and empty sections exclude each other).
void apply_overrides(toml::table& table, const std::vector<Override>& overrides);

// The scene as TOML text, to store next to its outputs.
std::string scene_to_toml(const toml::table& table);

}  // namespace bedforge::pipeline
