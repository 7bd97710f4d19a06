#include "app/commands.hpp"

#include <CLI/CLI.hpp>
#include <fmt/chrono.h>
#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "app/flags.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "pipeline/directory_stages.hpp"
#include "pipeline/run_scene.hpp"
#include "pipeline/scene.hpp"
#include "pipeline/scene_reference.hpp"

namespace bedforge {

namespace fs = std::filesystem;
using pipeline::Override;

namespace {

toml::table load_table(const std::string& scene_file) {
  if (scene_file.empty()) return {};
  return parse_scene_text(read_file(scene_file), scene_file);
}

#ifdef BEDFORGE_HAVE_VOLUME_MESH  // only `piece` has such options
// A number option's check that says what is allowed (CLI11's own range checks print the whole
// range of a double): "--wall-gap-m: -1; allowed: a number > 0 (m)".
CLI::Validator allowed_number(bool (*ok)(double), const std::string& what) {
  return CLI::Validator(
      [ok, what](std::string& text) {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool number = end != text.c_str() && *end == '\0';
        return number && ok(value) ? std::string() : text + "; allowed: " + what;
      },
      "");
}
#endif

}  // namespace

int run_command_line(int argc, char** argv) {
  CLI::App app{fmt::format("bedforge {}: packed beds of spheres, from a scene file to a bed, its analysis, the "
                           "fluid-domain surface, a volume mesh and an OpenFOAM case.\n"
                           "Exit status: 0 done, 2 bad input, 3 did not converge, 4 case written but not solved (no "
                           "OpenFOAM), 1 internal error.",
                           kVersion),
               "bedforge"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(kVersion));
  pipeline::Console console;
  bool no_progress = false;
  app.add_flag("--quiet", console.quiet, "print no summary lines");
  app.add_flag("--no-progress", no_progress, "no progress line even on a terminal (default: shown on a terminal, "
                                             "never when CI is set)");

  std::string dir, scene_file;
  bool overwrite = false, force = false;
  const char* force_help =
      "redo every stage; otherwise a stage whose inputs are unchanged (its scene sections, the stage before it and "
      "the bedforge version) is reused from DIR";
  SceneFlags flags;

  CLI::App* run = app.add_subcommand("run", "run the stages a scene's [outputs] need; writes into -o DIR");
  run->add_option("scene", scene_file, "TOML scene file")->required();
  run->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  run->add_flag("--overwrite", overwrite, "replace DIR/case when the scene's case must be made again and it exists");
  run->add_flag("--force", force, force_help);
  flags.add_to(*run, Command::run);

  CLI::App* pack = app.add_subcommand("pack", "pack spheres: writes DIR/bed.csv, bed.vtp, scene.toml, report.json");
  pack->add_option("--scene", scene_file, "TOML scene file to start from; options below override it");
  pack->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  pack->add_flag("--force", force, force_help);
  flags.add_to(*pack, Command::pack);

  std::string import_file;
  CLI::App* imp = app.add_subcommand("import", "bring in a bed made elsewhere (a DEM code's output), like pack");
  imp->add_option("file", import_file, "the bed file, in the format --format names")->required();
  imp->add_option("--scene", scene_file, "TOML scene file for [container] and [analysis]");
  imp->add_option("-o,--output", dir, "output directory (created if missing)")->required();
  flags.add_to(*imp, Command::import);

  // A stage run on a directory an earlier stage wrote: DIR and the options of that stage.
  auto on_directory = [&](const char* name, const char* what, const char* holding, Command command) {
    CLI::App* sub = app.add_subcommand(name, what);
    sub->add_option("dir", dir, holding)->required();
    flags.add_to(*sub, command);
    return sub;
  };
  CLI::App* analyse = on_directory("analyse", "analyse DIR/bed.csv: profiles, contacts; adds to DIR/report.json",
                                   "directory holding bed.csv (as written by pack or import)", Command::analyse);
  analyse->alias("analyze");
#ifdef BEDFORGE_HAVE_CGAL
  CLI::App* surface = on_directory("surface",
                                   "treat contacts and build the fluid-domain surface of DIR/bed.csv: writes fluid.stl "
                                   "(a named solid per patch), fluid_PATCH.stl, bed.stl, fluid.vtp",
                                   "directory holding bed.csv (as written by pack or import)", Command::surface);
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  CLI::App* mesh = on_directory("mesh",
                                "mesh the fluid domain of DIR/fluid.stl with gmsh, held to the quality gate: writes "
                                "DIR/fluid.msh (bad_cells.vtk when the gate fails)",
                                "directory holding fluid.stl and bed.csv (as written by surface)", Command::mesh);
  // One rank's piece of a decomposed case: started by `mpirun -np P bedforge piece DIR`, each
  // process takes its piece from Open MPI's rank unless told.
  int piece = -1, pieces = 0;
  std::vector<double> planes_d;
  double wall_gap_m = 0.0;
  CLI::App* piece_cmd =
      on_directory("piece",
                   "mesh one axial piece of DIR/bed.csv and write it as DIR/case/processorK with processor patches "
                   "to its neighbours (DIR/case written first); under mpirun each rank takes its own piece",
                   "directory holding bed.csv, scene.toml and case/",
                   static_cast<Command>(static_cast<unsigned>(Command::surface) | static_cast<unsigned>(Command::mesh) |
                                        static_cast<unsigned>(Command::case_)));
  piece_cmd->add_option("--piece", piece, "int: this piece, 0 at the bottom (default: OMPI_COMM_WORLD_RANK)")
      ->check(allowed_number([](double v) { return v >= 0.0; }, "an integer >= 0"));
  piece_cmd->add_option("--pieces", pieces, "int: the number of pieces (default: OMPI_COMM_WORLD_SIZE)")
      ->check(allowed_number([](double v) { return v >= 1.0; }, "an integer >= 1"));
  piece_cmd->add_option("--planes-d", planes_d,
                        "numbers: the heights of the planes between the pieces, d above the floor, one fewer than the "
                        "pieces (default: at about equal cells by the mesh estimate)");
  piece_cmd->add_option("--wall-gap-m", wall_gap_m,
                        "number, m: the whole bed's narrowest gap at a curved wall, whose edge every piece rings its "
                        "walls with, inf where none (default: found by surveying the bed's contacts first)")
      ->check(allowed_number([](double v) { return v > 0.0; }, "a number > 0 (m)"));
#endif
#ifdef BEDFORGE_HAVE_GMSH
  CLI::App* case_cmd = on_directory("case",
                                    "write the OpenFOAM case DIR/case from DIR/fluid.msh, or with --mesher snappy from "
                                    "DIR/fluid.stl (simpleFoam, laminar); run it with DIR/case/Allrun [-np N]",
                                    "directory holding fluid.msh (as written by mesh), or fluid.stl", Command::case_);
  case_cmd->add_flag("--overwrite", overwrite, "replace DIR/case when it exists");
#endif

  CLI::App* keys = app.add_subcommand("scene-keys", "print every scene key with its type, unit, default, allowed "
                                                    "values and meaning, as Markdown (docs/scene_reference.md)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (no_progress) console.progress = false;

  if (*keys) {
    const std::string today = fmt::format("{:%Y-%m-%d}", fmt::gmtime(std::time(nullptr)));
    std::fputs(pipeline::scene_reference_page(kVersion, today).c_str(), stdout);
    return 0;
  }
  if (*run || *pack || *imp) {
    toml::table table = load_table(scene_file);
    std::vector<Override> overrides;
    if (*imp) {
      overrides.push_back({"packing.algorithm", std::string("import")});
      overrides.push_back({"packing.file", fs::absolute(import_file).string()});
    }
    for (Override& o : flags.overrides()) overrides.push_back(std::move(o));
    pipeline::apply_overrides(table, overrides);
    const pipeline::Scene scene = pipeline::read_scene(table, scene_file.empty() ? "command line" : scene_file,
                                                       scene_file.empty() ? fs::path() : fs::path(scene_file).parent_path());
    const pipeline::Wants wants = *run ? pipeline::run_wants(scene) : pipeline::pack_wants(scene);
    pipeline::run_scene(scene, dir, {wants, overwrite, force}, console);
    return 0;
  }
  if (*analyse) pipeline::analyse_directory(dir, flags.overrides(), console);
#ifdef BEDFORGE_HAVE_CGAL
  if (*surface) pipeline::surface_directory(dir, flags.overrides(), console);
#endif
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  if (*mesh) pipeline::mesh_directory(dir, flags.overrides(), console);
  if (*piece_cmd) {
    // Open MPI's rank and size when the option is not given.
    auto from_mpi = [&](int& value, const char* option, const char* variable) {
      if (piece_cmd->count(option) > 0) return;
      const char* set = std::getenv(variable);
      if (!set)
        throw InputError(fmt::format("bedforge piece: {} not given and {} not set (not started by Open MPI's mpirun)",
                                     option, variable));
      value = std::stoi(set);
    };
    from_mpi(piece, "--piece", "OMPI_COMM_WORLD_RANK");
    from_mpi(pieces, "--pieces", "OMPI_COMM_WORLD_SIZE");
    if (piece >= pieces)
      throw InputError(fmt::format("--piece {}: allowed: 0 to {} (--pieces {})", piece, pieces - 1, pieces));
    pipeline::piece_directory(dir, flags.overrides(), piece, pieces, planes_d, wall_gap_m, console);
  }
#endif
#ifdef BEDFORGE_HAVE_GMSH
  if (*case_cmd) pipeline::case_directory(dir, flags.overrides(), overwrite, console);
#endif
  return 0;
}

}  // namespace bedforge
