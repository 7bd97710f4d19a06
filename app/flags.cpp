#include "app/flags.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "core/error.hpp"

namespace bedforge {

namespace {

constexpr unsigned operator|(Command a, Command b) { return static_cast<unsigned>(a) | static_cast<unsigned>(b); }
constexpr unsigned operator|(unsigned a, Command b) { return a | static_cast<unsigned>(b); }

struct Flag {
  const char* name;               // "--aspect-ratio"
  std::vector<const char*> keys;  // the scene keys it sets, all to the same value
  const char* what;               // what it is, in words
  unsigned commands;              // Command bits
  int values = 1;                 // values it takes, for an array key
};

constexpr unsigned kBed = Command::run | Command::pack | Command::import;  // the container
constexpr unsigned kPacking = Command::run | Command::pack;

// In the order they are applied, so of two lengths in different units the later wins.
const std::vector<Flag>& table() {
  static const std::vector<Flag> flags = {
      {"--algorithm", {"packing.algorithm"}, "packing algorithm", kPacking},
      {"--container", {"container.type"}, "container shape", kBed},
      {"--inner-aspect-ratio", {"container.inner_diameter_d"}, "annulus inner diameter in particle diameters", kBed},
      {"--box-size-d", {"container.size_x_d", "container.size_y_d"}, "box side in particle diameters, both sides", kBed},
      {"--periodic", {"container.periodic_x", "container.periodic_y"}, "box with periodic sides", kBed},
      {"--temperature", {"packing.monte_carlo.temperature"}, "Monte Carlo kT / (m* g d)", kPacking},
      {"--shakes", {"packing.monte_carlo.shakes"}, "Monte Carlo shakes", kPacking},
      {"--mixing-cycles", {"packing.monte_carlo.mixing_cycles"}, "Monte Carlo cycles without gravity", kPacking},
      {"--settling-cycles", {"packing.monte_carlo.settling_cycles"}, "Monte Carlo cycles after the shakes", kPacking},
      {"--aspect-ratio", {"container.diameter_d"}, "container diameter in particle diameters, D/d", kBed},
      {"--container-diameter-m", {"container.diameter_m"}, "container diameter in metres", kBed},
      {"--count", {"particles.count"}, "number of spheres", kPacking},
      {"--diameter-m", {"particles.diameter_m"}, "sphere diameter in metres, equal spheres", kPacking},
      {"--seed", {"packing.seed"}, "random seed", kPacking},
      {"--mode", {"packing.soft_sphere.mode"}, "soft-sphere schedule", kPacking},
      {"--initial-void-fraction", {"packing.soft_sphere.initial_void_fraction"}, "eps_0 of the generation stage",
       kPacking},
      {"--stiffness-step", {"packing.soft_sphere.stiffness_step"}, "C_k of Eq. (4), faithful mode", kPacking},
      {"--overlap-tolerance-d", {"packing.soft_sphere.overlap_tolerance_d"},
       "final overlap tolerance in smallest diameters", kPacking},
      {"--max-iterations", {"packing.soft_sphere.max_iterations"}, "iteration cap over all stages", kPacking},
      {"--format", {"packing.format"},
       "the file's format: rows x y z d; a LAMMPS/LIGGGHTS text dump (last snapshot, columns x y z and radius or "
       "diameter); Yade's export.text (x y z r)",
       static_cast<unsigned>(Command::import)},
      {"--units", {"packing.units"}, "length unit of the file", static_cast<unsigned>(Command::import)},
      {"--origin-m", {"packing.origin_m"},
       "metres: the point of the file's frame on the container axis at the floor, moved to bedforge's origin",
       static_cast<unsigned>(Command::import), 3},
      {"--exclude-d", {"analysis.exclude_d"}, "diameters left out at floor and top for central values",
       static_cast<unsigned>(Command::analyse)},
      {"--radial-bin-d", {"analysis.radial_bin_d"}, "radial bin width in diameters",
       static_cast<unsigned>(Command::analyse)},
      {"--axial-bin-d", {"analysis.axial_bin_d"}, "axial bin height in diameters",
       static_cast<unsigned>(Command::analyse)},
      {"--contact-tolerance-d", {"analysis.contact_tolerance_d"},
       "largest gap counted as a contact, in smallest diameters", static_cast<unsigned>(Command::analyse)},
      {"--contacts", {"contacts.treatment"}, "contact treatment", static_cast<unsigned>(Command::surface)},
      {"--wall-contacts", {"contacts.wall_treatment"}, "treatment of sphere-wall contacts",
       static_cast<unsigned>(Command::surface)},
      {"--shrink-factor", {"contacts.shrink_factor"}, "sphere scale for shrink", static_cast<unsigned>(Command::surface)},
      {"--enlarge-factor", {"contacts.enlarge_factor"}, "sphere scale for enlarge",
       static_cast<unsigned>(Command::surface)},
      {"--bridge-diameter-d", {"contacts.bridge_diameter_d"}, "bridge diameter in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--bridge-gap-d", {"contacts.bridge_gap_d"}, "gaps below this get a bridge, in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--cap-gap-d", {"contacts.cap_gap_d"}, "gap caps leave, in diameters", static_cast<unsigned>(Command::surface)},
      {"--edge-length-d", {"surface.edge_length_d"}, "target triangle edge in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--contact-edge-length-d", {"surface.contact_edge_length_d"}, "edge where treated contacts meet, in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--cells-per-gap", {"surface.cells_per_gap"},
       "cells across narrow gaps: edges shrink to gap / this where a surface faces another closer than this x the "
       "edge length, not below the contact edge; 0 for none",
       static_cast<unsigned>(Command::surface)},
      {"--min-angle-deg", {"surface.min_angle_deg"},
       "quality gate: smallest triangle angle allowed in degrees, else the stage fails and writes "
       "bad_triangles.vtp",
       static_cast<unsigned>(Command::surface)},
      {"--inlet-length-d", {"surface.inlet_length_d"}, "empty section below the bed in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--outlet-length-d", {"surface.outlet_length_d"}, "empty section above the bed in diameters",
       static_cast<unsigned>(Command::surface)},
      {"--clip-window-d", {"surface.clip_window_d"},
       "heights above the floor in diameters whose planes become the inlet and outlet, cutting the spheres there, "
       "instead of the empty sections",
       static_cast<unsigned>(Command::surface), 2},
      {"--at-clip-planes", {"contacts.at_clip_planes"},
       "what the clip window's planes do to the bridges, caps and unions they cross: open them (spheres shrunk) or "
       "cut them through",
       static_cast<unsigned>(Command::surface)},
      {"--algorithm", {"mesh.algorithm"}, "first 3D algorithm tried, the other is the fallback",
       static_cast<unsigned>(Command::mesh)},
      {"--max-size-d", {"mesh.max_size_d"}, "largest cell edge in diameters", static_cast<unsigned>(Command::mesh)},
      {"--max-non-orthogonality", {"mesh.gate.max_non_orthogonality_deg"}, "quality gate in degrees",
       static_cast<unsigned>(Command::mesh)},
      {"--layers", {"mesh.layers.count"}, "prism layers on the particle surfaces", static_cast<unsigned>(Command::mesh)},
      {"--layer-thickness-d", {"mesh.layers.thickness_d"},
       "total thickness of the prism layers in diameters where the gaps allow it", static_cast<unsigned>(Command::mesh)},
      {"--reynolds", {"case.reynolds"}, "particle Reynolds number of the superficial velocity",
       static_cast<unsigned>(Command::case_)},
      {"--iterations", {"case.iterations"}, "simpleFoam iteration cap", static_cast<unsigned>(Command::case_)},
      {"--processors", {"case.processors"}, "subdomains in decomposeParDict", static_cast<unsigned>(Command::case_)},
      {"--format", {"case.format"}, "polyMesh and field format", static_cast<unsigned>(Command::case_)},
      {"--cells", {"case.cells"}, "the cells solved on: gmsh's tetrahedra or their dual polyhedra",
       static_cast<unsigned>(Command::case_)},
      {"--snappy", {"case.snappy"}, "also write the snappyHexMesh set-up, used by Allrun -snappy",
       static_cast<unsigned>(Command::case_)},
      {"--mesher", {"case.mesher"},
       "what makes the cells solved on: gmsh (the mesh stage) or snappy (snappyHexMesh in Allrun, on every "
       "process, and no gmsh mesh; not validated, check its cells)",
       static_cast<unsigned>(Command::case_)},
      {"--run", {"case.run"}, "run Allrun and add the pressure drop to the report",
       static_cast<unsigned>(Command::case_)},
  };
  return flags;
}

std::string joined(const std::vector<const char*>& keys) {
  std::string out;
  for (const char* k : keys) out += (out.empty() ? "" : " and ") + std::string(k);
  return out;
}

// The type of a row's values as help shows it; CLI11 adds "x N" for a row of N values.
std::string type_name(const KeySpec& spec) {
  return spec.type.ends_with("...") ? spec.type.substr(0, spec.type.size() - 3) : spec.type;
}

// The generated help of a row: what it is, its range, the keys it sets, its default.
std::string help(const Flag& f, const KeySpec& spec) {
  if (spec.type == "BOOL") return fmt::format("{} (sets {} = true)", f.what, joined(f.keys));
  return fmt::format("{} ({}; sets {}); default {}", f.what, spec.allowed, joined(f.keys), spec.fallback);
}

template <class T>
T parse_number(const Flag& f, const KeySpec& spec, const std::string& text) {
  std::size_t used = 0;
  try {
    const T v = std::is_integral_v<T> ? static_cast<T>(std::stoll(text, &used)) : static_cast<T>(std::stod(text, &used));
    if (used == text.size()) return v;
  } catch (const std::logic_error&) {
    // not a number: said below
  }
  throw InputError(fmt::format("{} (sets {}): got '{}'; allowed: {}", f.name, joined(f.keys), text, spec.allowed));
}

}  // namespace

SceneFlags::SceneFlags() : schema_(pipeline::scene_schema()), given_(table().size()) {}

void SceneFlags::add_to(CLI::App& app, Command command) {
  for (std::size_t row = 0; row < table().size(); ++row) {
    const Flag& f = table()[row];
    if (!(f.commands & static_cast<unsigned>(command))) continue;
    const KeySpec& spec = schema_.at(f.keys.front());
    if (spec.type == "BOOL") {
      app.add_flag_callback(f.name, [this, row] { given_[row] = {"true"}; }, help(f, spec));
    } else {
      app.add_option(f.name, given_[row], help(f, spec))->expected(f.values)->type_name(type_name(spec));
    }
  }
}

std::vector<pipeline::Override> SceneFlags::overrides() const {
  std::vector<pipeline::Override> out;
  for (std::size_t row = 0; row < table().size(); ++row) {
    const std::vector<std::string>& v = given_[row];
    if (v.empty()) continue;
    const Flag& f = table()[row];
    const KeySpec& spec = schema_.at(f.keys.front());
    for (const char* key : f.keys) {
      if (spec.type == "BOOL") {
        out.push_back({key, true});
      } else if (spec.type == "INT") {
        out.push_back({key, parse_number<long long>(f, spec, v.front())});
      } else if (spec.type == "FLOAT") {
        out.push_back({key, parse_number<double>(f, spec, v.front())});
      } else if (spec.type == "FLOAT...") {
        std::vector<double> numbers;
        for (const std::string& s : v) numbers.push_back(parse_number<double>(f, spec, s));
        out.push_back({key, numbers});
      } else {
        out.push_back({key, v.front()});
      }
    }
  }
  return out;
}

}  // namespace bedforge
