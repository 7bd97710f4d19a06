#include "cases/openfoam_case.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <future>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <random>
#include <sstream>

#include <unistd.h>

#include "analysis/laminar_duct.hpp"
#include "analysis/pressure_drop.hpp"
#include "analysis/stokes_arrays.hpp"
#include "analysis/void_fraction.hpp"
#include "cases/poly_mesh_io.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/report.hpp"
#include "core/stage_meter.hpp"
#include "meshing/dual_mesh.hpp"

namespace bedforge::cases {

namespace fs = std::filesystem;

CaseParams read_case_params(SceneSection& s) {
  CaseParams p;
  p.reynolds = s.number("reynolds", p.reynolds, Range{0.0, 1000.0, true, false});
  p.density_kg_m3 = s.number("density_kg_m3", p.density_kg_m3, Range::positive());
  p.viscosity_pa_s = s.number("viscosity_pa_s", p.viscosity_pa_s, Range::positive());
  p.iterations = static_cast<int>(s.integer("iterations", p.iterations, 1, 1'000'000));
  p.residual_p = s.number("residual_p", p.residual_p, Range::open(0.0, 1.0));
  p.residual_u = s.optional_number("residual_u", Range::open(0.0, 1.0),
                                  fmt::format("{}; {} on cells with prism layers", kResidualU, kResidualULayered));
  p.processors = static_cast<int>(s.integer("processors", p.processors, 1, 4096));
  p.decomposition = s.choice("decomposition", p.decomposition, {"hierarchical", "scotch"});
  p.binary = s.choice("format", "binary", {"binary", "ascii"}) == "binary";
  p.polyhedra = s.choice("cells", "polyhedra", {"polyhedra", "tetrahedra"}) == "polyhedra";
  p.snappy_cells = s.choice("mesher", "gmsh", {"gmsh", "snappy"}) == "snappy";
  p.snappy = s.boolean("snappy", p.snappy) || p.snappy_cells;
  p.snappy_cell_d = s.number("snappy_cell_d", p.snappy_cell_d, Range::closed(0.01, 10.0));
  p.snappy_level = static_cast<int>(s.integer("snappy_level", p.snappy_level, 0, 6));
  p.slip_walls = s.choice("walls", "no_slip", {"no_slip", "slip"}) == "slip";
  p.section_exclude_d = s.number("section_exclude_d", p.section_exclude_d, Range::non_negative());
  p.run = s.boolean("run", p.run);
  SceneSection convergence = s.sub("convergence");
  // A solved case is studied by default: a pressure drop without its discretisation error is
  // half an answer (docs/defaults.md).
  const int study_levels = p.run && !p.snappy_cells ? kStudyLevels : 0;
  p.convergence.levels = static_cast<int>(convergence.integer(
      "levels", study_levels, 0, 6, fmt::format("{} when case.run = true on gmsh's cells, else 0", kStudyLevels)));
  p.convergence.ratio = convergence.number("ratio", p.convergence.ratio, Range::closed(1.1, 2.0));
  convergence.finish();
  if (p.convergence.levels == 1 || p.convergence.levels == 2)
    throw InputError(fmt::format("case.convergence.levels = {}: an order and an extrapolation need three meshes; "
                                 "allowed: 0 (no study) or 3 to 6",
                                 p.convergence.levels));
  if (p.convergence.levels > 0 && (!p.run || p.snappy_cells))
    throw InputError("case.convergence.levels > 0 needs the flow solved on gmsh's meshes; allowed: case.run = true "
                     "with case.mesher = \"gmsh\"");
  return p;
}

nlohmann::json to_json(const CaseParams& p) {
  return {{"reynolds", p.reynolds},         {"density_kg_m3", p.density_kg_m3},
          {"viscosity_pa_s", p.viscosity_pa_s}, {"iterations", p.iterations},
          {"residual_p", p.residual_p},     {"residual_u", p.residual_u ? nlohmann::json(*p.residual_u) : nlohmann::json()},
          {"processors", p.processors},     {"decomposition", p.decomposition},
          {"format", p.binary ? "binary" : "ascii"}, {"cells", p.polyhedra ? "polyhedra" : "tetrahedra"},
          {"snappy", p.snappy},             {"snappy_cell_d", p.snappy_cell_d},
          {"snappy_level", p.snappy_level}, {"section_exclude_d", p.section_exclude_d},
          {"walls", p.slip_walls ? "slip" : "no_slip"},
          {"run", p.run},                   {"mesher", p.snappy_cells ? "snappy" : "gmsh"},
          {"convergence", {{"levels", p.convergence.levels}, {"ratio", p.convergence.ratio}}}};
}

BedSection bed_section(const meshing::CellGeometry* cells, const CaseGeometry& g, double exclude_d) {
  // The bed between its floor and top, or the part of it a clip window kept.
  BedSection s{std::max(g.bed_bottom, g.inlet_z) + exclude_d * g.d_ref,
               std::min(g.bed_top, g.outlet_z) - exclude_d * g.d_ref, std::nullopt};
  if (s.z_high - s.z_low < 0.5 * g.d_ref)
    throw InputError(fmt::format("case.section_exclude_d = {}: leaves a bed section of {:.3g} d (bed height {:.3g} d); "
                                 "the pressure drop needs at least 0.5 d, lower it",
                                 exclude_d, (s.z_high - s.z_low) / g.d_ref, g.bed_top / g.d_ref));
  if (!cells) return s;
  const std::vector<Eigen::Vector3d>& c = cells->centres;
  const std::vector<double>& v = cells->volumes;
  double fluid = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k)
    if (c[k].z() > s.z_low && c[k].z() < s.z_high) fluid += v[k];
  s.void_fraction = fluid / (g.cross_section_area * (s.z_high - s.z_low));
  return s;
}

CaseGeometry case_geometry(const std::vector<Eigen::Vector3d>& points, const Bed& bed) {
  CaseGeometry g;
  g.d_ref = reference_diameter(bed);
  const Container& c = *bed.container;
  g.cross_section_area = c.cross_section_area();
  g.lateral_bounds = c.lateral_bounds();
  g.aspect_ratio = 4.0 * g.cross_section_area / c.wall_perimeter() / g.d_ref;  // hydraulic diameter over d
  g.inlet_z = std::numeric_limits<double>::infinity();
  g.outlet_z = -g.inlet_z;
  for (const auto& x : points) g.inlet_z = std::min(g.inlet_z, x.z()), g.outlet_z = std::max(g.outlet_z, x.z());
  const bool empty = bed.size() == 0;
  g.bed_bottom = empty ? g.inlet_z : 0.0;
  g.bed_top = empty ? g.outlet_z : bed_height(bed);
  return g;
}

Eigen::Vector3d fluid_point(const Bed& bed, const CaseGeometry& g) {
  // At most about 2e5 lattice points at cell centres (none on the inlet, the outlet or a box's
  // side). From each, the spheres are scanned outwards in height only as far as one could still
  // come nearer than the nearest found, so a bed of 1e5 spheres takes well under a second.
  const Eigen::Vector4d& b = g.lateral_bounds;
  const Eigen::Vector3d lo(b[0], b[1], g.inlet_z), hi(b[2], b[3], g.outlet_z);
  const double step = std::max(0.25 * g.d_ref, std::cbrt((hi - lo).prod() / 2e5));
  const Eigen::Array3i n = ((hi - lo) / step).array().floor().cast<int>().max(1);
  std::vector<std::size_t> order(bed.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return bed.centres[i].z() < bed.centres[j].z(); });
  std::vector<double> zs(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) zs[k] = bed.centres[order[k]].z();
  double r_max = 0.0;
  for (double dia : bed.diameters) r_max = std::max(r_max, 0.5 * dia);
  const Container& c = *bed.container;
  const Periodicity per = c.periodicity();
  Eigen::Vector3d best = 0.5 * (lo + hi);
  double best_clearance = -HUGE_VAL;
  for (int k = 0; k < n.z(); ++k)
    for (int i = 0; i < n.x(); ++i)
      for (int j = 0; j < n.y(); ++j) {
        const Eigen::Vector3d q =
            lo + ((Eigen::Array3d(i, j, k) + 0.5) * (hi - lo).array() / n.cast<double>()).matrix();
        const double ends = std::min(q.z() - g.inlet_z, g.outlet_z - q.z());
        double clearance = ends;
        // The walls: a sphere of that radius at q overlaps a wall by how much nearer the wall is.
        WallContact touch[Container::kMaxWallContacts];
        for (int w = 0, m = c.wall_contacts(q, ends, touch); w < m; ++w)
          clearance = std::min(clearance, ends - touch[w].overlap);
        const std::size_t at = std::lower_bound(zs.begin(), zs.end(), q.z()) - zs.begin();
        for (std::size_t up = at, down = at; clearance > best_clearance && (up < zs.size() || down > 0);) {
          const bool take_up = down == 0 || (up < zs.size() && zs[up] - q.z() < q.z() - zs[down - 1]);
          const std::size_t s = take_up ? up++ : --down;
          if (std::abs(zs[s] - q.z()) - r_max >= clearance) break;
          clearance =
              std::min(clearance, per.separation(bed.centres[order[s]], q).norm() - 0.5 * bed.diameters[order[s]]);
        }
        if (clearance > best_clearance) best_clearance = clearance, best = q;
      }
  return best;
}

nlohmann::json CaseInfo::to_json() const {
  return {{"directory", directory.string()},
          {"parameters", cases::to_json(params)},
          {"velocity_m_s", velocity_m_s},
          {"kinematic_viscosity_m2_s", kinematic_viscosity_m2_s},
          {"cells", cells},
          {"section",
           {{"z_low_m", section.z_low},
            {"z_high_m", section.z_high},
            {"void_fraction_mesh", section.void_fraction ? nlohmann::json(*section.void_fraction) : nullptr},
            {"void_fraction_bed", section.void_fraction_bed}}},
          {"aspect_ratio", aspect_ratio},
          {"inlet_area_m2", inlet_area_m2},
          {"d_ref_m", d_ref_m},
          {"fluid_volume_m3", fluid_volume_m3 ? nlohmann::json(*fluid_volume_m3) : nullptr},
          {"surface_volume_m3", surface_volume_m3 ? nlohmann::json(*surface_volume_m3) : nullptr},
          {"exact_pressure_gradient_pa_m", exact_pressure_gradient_pa_m ? nlohmann::json(*exact_pressure_gradient_pa_m) : nullptr}};
}

nlohmann::json FlowResult::to_json() const {
  nlohmann::json mesh = {{"mesher", mesher}};
  if (solved_cells >= 0) mesh["cells"] = solved_cells;
  if (solved_volume_m3) mesh["volume_m3"] = *solved_volume_m3;
  if (volume_lost) mesh["volume_lost"] = *volume_lost;
  nlohmann::json allrun = nlohmann::json::array();
  for (const Step& s : steps) allrun.push_back({{"step", s.name}, {"time_s", s.time_s}, {"peak_memory_mb", s.peak_memory_mb}});
  nlohmann::json j = {{"time_s", time_s},
          {"solver_peak_memory_mb", solver_peak_memory_mb},
          {"allrun_steps", allrun},
          {"mesh", mesh},
          {"iterations", iterations},
          {"history", history},
          {"converged", converged},
          {"final_initial_residual", {{"U", residual_u}, {"p", residual_p}}},
          {"pressure_gradient_bed_pa_m", pressure_gradient_bed_pa_m},
          {"pressure_gradient_change_last_tenth", pressure_gradient_change_last_tenth},
          {"pressure_drop_inlet_outlet_pa", pressure_drop_inlet_outlet_pa},
          {"flow_rate_m3_s", flow_rate_m3_s},
          {"flow_rate_relative_error", flow_rate_relative_error},
          {"drag",
           {{"walls_n", drag_walls_n},
            {"walls_viscous_n", drag_walls_viscous_n},
            {"particles_n", drag_particles_n},
            {"particles_viscous_n", drag_particles_viscous_n},
            {"push_inlet_outlet_n", push_inlet_outlet_n},
            {"wall_share", wall_share_of_drag},
            {"force_balance_relative_error", force_balance_relative_error}}}};
  if (exact_pa_m) {
    j["exact_pa_m"] = *exact_pa_m;
    j["relative_error_to_exact"] = relative_error_to_exact;
  } else {
    auto known = [](const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(); };
    j["eisfeld_schnitzlein_pa_m"] = known(eisfeld_schnitzlein_pa_m);
    j["ratio_to_eisfeld_schnitzlein"] = known(ratio_to_eisfeld_schnitzlein);
    j["void_fraction_section"] = known(void_fraction_section);
    j["eisfeld_schnitzlein_bed_pa_m"] = eisfeld_schnitzlein_bed_pa_m;
    j["ratio_to_eisfeld_schnitzlein_bed"] = ratio_to_eisfeld_schnitzlein_bed;
    j["void_fraction_section_bed"] = void_fraction_section_bed;
    j["drag"]["wall_share_eisfeld_schnitzlein"] = wall_share_of_drag_eisfeld_schnitzlein;
  }
  return j;
}

namespace {

void write_text(const fs::path& path, const std::string& text, bool executable = false) {
  write_file_atomically(path, text);
  if (executable)
    fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add);
}

std::string dict(const std::string& cls, const std::string& location, const std::string& object,
                 const std::string& note, const std::string& body) {
  return foam_header(cls, location, object, note) + body +
         "\n// ************************************************************************* //\n";
}

// Walls and particles take the same conditions unless `particles` gives the particles their own
// (walls that slip); `.*wall` matches wall and inner_wall. The constraint types cover processor
// patches, so the fields serve snappyHexMesh's cells as they come, decomposed.
std::string boundary_field(const std::string& inlet, const std::string& outlet, const std::string& walls,
                           const std::string& particles = {}) {
  const std::string solids = particles.empty() ? fmt::format("    \"(.*wall|particles)\"\n    {{\n{}    }}\n", walls)
                                               : fmt::format("    \".*wall\"\n    {{\n{}    }}\n"
                                                             "    particles\n    {{\n{}    }}\n",
                                                             walls, particles);
  return fmt::format("boundaryField\n{{\n    #includeEtc \"caseDicts/setConstraintTypes\"\n"
                     "    inlet\n    {{\n{}    }}\n    outlet\n    {{\n{}    }}\n{}}}\n",
                     inlet, outlet, solids);
}

std::string surface_value(const std::string& name, const std::string& region, const std::string& operation,
                          const std::string& field) {
  return fmt::format("    {}\n    {{\n        type            surfaceFieldValue;\n"
                     "        libs            (\"libfieldFunctionObjects.so\");\n        writeControl    timeStep;\n"
                     "        writeInterval   1;\n        log             false;\n        writeFields     false;\n"
                     "{}        operation       {};\n        fields          ({});\n    }}\n",
                     name, region, operation, field);
}

// OpenFOAM's forces on the patches `patches` matches (a list of names or quoted regular
// expressions), with the density that turns the kinematic pressure into Pa. Evaluated only
// when the fields are written (at the end), as each evaluation takes the gradient of U.
std::string forces(const std::string& name, const std::string& patches, double density) {
  return fmt::format("    {}\n    {{\n        type            forces;\n        libs            (\"libforces.so\");\n"
                     "        executeControl  writeTime;\n        writeControl    writeTime;\n        log             false;\n"
                     "        patches         ({});\n        rho             rhoInf;\n        rhoInf          {:.12g};\n"
                     "        CofR            (0 0 0);\n    }}\n",
                     name, patches, density);
}

std::string patch_region(const std::string& patch) {
  return fmt::format("        regionType      patch;\n        name            {};\n", patch);
}

std::string plane_region(const std::string& name, double z) {
  return fmt::format("        regionType      sampledSurface;\n        name            {};\n"
                     "        sampledSurfaceDict\n        {{\n            type        cuttingPlane;\n"
                     "            planeType   pointAndNormal;\n            pointAndNormalDict\n            {{\n"
                     "                point   (0 0 {:.12g});\n                normal  (0 0 1);\n            }}\n"
                     "            interpolate false;\n        }}\n",
                     name, z);
}

// Allrun: the cells (the gmsh mesh as written, its polyhedral dual, or snappyHexMesh's), then
// simpleFoam, on N processes with -np N. snappyHexMesh's cells stay decomposed for the solver,
// and its results with them: gathering them would take one process the whole mesh's memory.
// It ends by printing the bed's pressure gradient over `section`, as run_case reads it.
std::string allrun(const CaseParams& p, const BedSection& section) {
  const bool flag = p.snappy && !p.snappy_cells;  // gmsh's cells, snappyHexMesh's on request
  std::string s = "#!/bin/sh\n";
  s += p.snappy_cells
           ? "# Runs the case: snappyHexMesh makes the cells from constant/triSurface/fluid.stl, then simpleFoam\n"
             "# solves; ./Allrun (serial) or ./Allrun -np N (N processes; the mesh and the results stay in\n"
             "# processor*/, which ParaView opens as a decomposed case).\n"
           : "# Runs the case: ./Allrun (serial) or ./Allrun -np N (decomposePar, mpirun, reconstructPar).\n";
  if (flag) s += "# ./Allrun -snappy first replaces the gmsh mesh by one from snappyHexMesh (decomposed with -np N).\n";
  s += "cd \"${0%/*}\" || exit 1\n"
       "export WM_PROJECT_DIR=\"${WM_PROJECT_DIR:-/usr/share/openfoam}\"\n"
       "np=1\n" + std::string(p.snappy_cells ? "snappy=1\n" : "snappy=0\n") +
       "while [ $# -gt 0 ]; do\n"
       "    case \"$1\" in\n"
       "        -np) np=\"$2\"; shift 2 ;;\n";
  if (flag) s += "        -snappy) snappy=1; shift ;;\n";
  s += "        *) echo \"usage: ./Allrun [-np N]" + std::string(flag ? " [-snappy]" : "") +
       "\" >&2; exit 2 ;;\n"
       "    esac\n"
       "done\n"
       "# Each step logs to log.<step>; with GNU time its wall time (s) and its largest process's peak\n"
       "# memory (kB) go to log.time.\n"
       "rm -f log.time\n"
       "if [ -x /usr/bin/time ]; then\n"
       "    timed() { /usr/bin/time -a -o log.time -f \"$name %e %M\" \"$@\"; }\n"
       "else\n"
       "    timed() { \"$@\"; }\n"
       "fi\n"
       "step() { name=\"$1\"; shift; timed \"$@\" > \"log.$name\" 2>&1 || { echo \"$name failed, see log.$name\" >&2; exit 1; }; }\n"
       "run() { echo \"running $*\"; step \"$1\" \"$@\"; }\n"
       "# Open MPI refuses root unless told (containers, CI).\n"
       "[ \"$(id -u)\" = 0 ] && export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1\n"
       "parallel() {\n"
       "    echo \"running $* on $np processes\"\n"
       "    step \"$1\" mpirun -np \"$np\" \"$@\" -parallel\n"
       "}\n"
       "decompose() {\n"
       "    sed -i -e \"s/^numberOfSubdomains .*/numberOfSubdomains $np;/\" \\\n"
       "        -e \"s/^    n .*/    n               (1 1 $np);/\" system/decomposeParDict\n"
       "    run decomposePar -force \"$@\"\n"
       "}\n";
  if (p.snappy)
    s += "if [ \"$snappy\" = 1 ]; then\n"
         "    run blockMesh\n"
         "    run surfaceFeatureExtract\n"
         "    if [ \"$np\" -gt 1 ]; then\n"
         "        decompose -copyZero  # the background mesh's patches are not the fields' patches\n"
         "        parallel snappyHexMesh -overwrite\n"
         "        parallel checkMesh\n"
         "    else\n"
         "        run snappyHexMesh -overwrite\n"
         "        run checkMesh\n"
         "    fi\n"
         "fi\n";
  if (p.polyhedra && !p.snappy_cells)
    s += "# constant/polyMesh holds the dual polyhedra of gmsh's tetrahedra, as `polyDualMesh 80` makes them:\n"
         "# an empty tube's pressure drop converges to the exact one on the dual, not on the tetrahedra.\n"
         "if [ \"$snappy\" = 0 ]; then\n"
         "    run checkMesh\n"
         "fi\n";
  s += "# Past about a million cells per process the solver's temporary fields outgrow glibc's 32 MB\n"
       "# limit for heap blocks: each was mapped afresh and cleared page by page on every use, which\n"
       "# made an iteration ten times slower. Kept in the heap, they are reused (a larger peak); the\n"
       "# setting holds for every step from here on.\n"
       "export MALLOC_MMAP_MAX_=0 MALLOC_TRIM_THRESHOLD_=1000000000000\n"
       "if [ \"$np\" -gt 1 ]; then\n"
       "    [ \"$snappy\" = 1 ] || decompose\n"
       "    parallel simpleFoam\n"
       "    [ \"$snappy\" = 1 ] || run reconstructPar -latestTime\n"
       "else\n"
       "    run simpleFoam\n"
       "fi\n";
  // The result: the kinematic pressure the solver averaged over each section plane at its last
  // iteration, their difference times the density over the planes' distance.
  s += fmt::format(
      "# The bed's pressure gradient between the section planes z = {0:.12g} and {1:.12g} m, from the\n"
      "# last rows of the pressure averaged over each plane (kinematic, times rho = {2:.12g} kg/m3).\n"
      "bottom=postProcessing/pBedBottom/0/surfaceFieldValue.dat\n"
      "top=postProcessing/pBedTop/0/surfaceFieldValue.dat\n"
      "awk -v rho={2:.12g} -v zl={0:.12g} -v zh={1:.12g} -v b=\"$bottom\" -v t=\"$top\" '\n"
      "    FNR == 1 {{ file++ }}\n"
      "    /^#/ {{ next }}\n"
      "    file == 1 {{ pb = $2; nb++ }}\n"
      "    file == 2 {{ pt = $2; nt++ }}\n"
      "    END {{\n"
      "        if (!nb || !nt) {{ print \"no pressure on the section planes in \" b \" or \" t > \"/dev/stderr\"; exit 1 }}\n"
      "        printf \"dp/L over the bed section (z = %.6g to %.6g m): %.6g Pa/m\\n\", zl, zh, rho * (pb - pt) / (zh - zl)\n"
      "        print \"  from the last rows of \" b \" and \" t\n"
      "    }}' \"$bottom\" \"$top\" || exit 1\n",
      section.z_low, section.z_high, p.density_kg_m3);
  return s;
}

const char* kAllclean =
    "#!/bin/sh\n"
    "# Removes what Allrun made: results, logs, processor directories; keeps the mesh and 0/.\n"
    "cd \"${0%/*}\" || exit 1\n"
    "rm -rf processor* postProcessing log.* [1-9]* 0.[0-9]*\n";

}  // namespace

void refuse_existing_case(const fs::path& case_dir, bool overwrite) {
  if (!overwrite && fs::exists(case_dir))
    throw InputError(fmt::format("{} exists; remove it or pass --overwrite", case_dir.string()));
}

CaseInfo write_case(const fs::path& case_dir, bool overwrite, const meshing::PolyMesh* mesh,
                    const std::vector<std::string>& patches, const CaseGeometry& g, const Bed& bed,
                    const CaseParams& given, const std::string& note, const std::string& scene_toml,
                    const std::string& bed_csv, const fs::path& fluid_stl, bool spheres_as_packed) {
  refuse_existing_case(case_dir, overwrite);
  CaseParams p = given;
  if (!p.residual_u) p.residual_u = mesh && meshing::has_prisms(*mesh) ? kResidualULayered : kResidualU;
  std::random_device rd;
  const fs::path tmp = case_dir.parent_path() / fmt::format(".{}.partial-{:x}", case_dir.filename().string(), rd());
  const double nu = p.viscosity_pa_s / p.density_kg_m3;
  const double u = p.reynolds * nu / g.d_ref;  // superficial velocity
  const std::optional<meshing::CellGeometry> geometry =
      mesh ? std::optional(meshing::cell_geometry(*mesh)) : std::nullopt;
  BedSection section = bed_section(geometry ? &*geometry : nullptr, g, p.section_exclude_d);
  section.void_fraction_bed = analysis::void_fraction(bed, section.z_low, section.z_high);
  long cells = mesh ? mesh->cells : 0;  // as written
  try {
    // On polyhedra the case holds the dual of gmsh's cells, made here as `polyDualMesh 80` makes
    // it (which peaked at about 1 kB per tetrahedron).
    if (mesh && p.polyhedra && !p.snappy_cells) {
      const meshing::PolyhedralMesh dual = meshing::dual_mesh(*mesh, geometry->centres, kDualFeatureAngleDeg);
      write_poly_mesh(tmp / "constant/polyMesh", dual, p.binary, note);
      cells = dual.cells;
    } else if (mesh) {
      write_poly_mesh(tmp / "constant/polyMesh", *mesh, p.binary, note);
    }
    const std::string fmt_word = p.binary ? "binary" : "ascii";
    auto field_dict = [&](const std::string& cls, const std::string& object, const std::string& body) {
      return foam_header(cls, "0", object, note, false) + body;
    };
    write_text(tmp / "0/U",
               field_dict("volVectorField", "U",
                          fmt::format("// superficial velocity {:.6g} m/s: Re_p = {} with d = {:.6g} m, nu = {:.6g} m2/s\n"
                                      "dimensions      [0 1 -1 0 0 0 0];\n\ninternalField   uniform (0 0 {:.12g});\n\n",
                                      u, p.reynolds, g.d_ref, nu, u) +
                              boundary_field(fmt::format("        type            fixedValue;\n"
                                                         "        value           uniform (0 0 {:.12g});\n",
                                                         u),
                                             "        type            inletOutlet;\n"
                                             "        inletValue      uniform (0 0 0);\n"
                                             "        value           uniform (0 0 0);\n",
                                             p.slip_walls ? "        type            slip;\n" : "        type            noSlip;\n",
                                             p.slip_walls ? "        type            noSlip;\n" : "")));
    write_text(tmp / "0/p", field_dict("volScalarField", "p",
                                       "// kinematic pressure p/rho\ndimensions      [0 2 -2 0 0 0 0];\n\n"
                                       "internalField   uniform 0;\n\n" +
                                           boundary_field("        type            zeroGradient;\n",
                                                          "        type            fixedValue;\n"
                                                          "        value           uniform 0;\n",
                                                          "        type            zeroGradient;\n")));
    write_text(tmp / "constant/transportProperties",
               dict("dictionary", "constant", "transportProperties", note,
                    fmt::format("transportModel  Newtonian;\n\nnu              {:.12g};  // mu/rho = {} / {}\n", nu,
                                p.viscosity_pa_s, p.density_kg_m3)));
    write_text(tmp / "constant/turbulenceProperties",
               dict("dictionary", "constant", "turbulenceProperties", note, "simulationType  laminar;\n"));
    const std::string functions =
        surface_value("pInlet", patch_region("inlet"), "areaAverage", "p") +
        surface_value("pOutlet", patch_region("outlet"), "areaAverage", "p") +
        surface_value("pBedBottom", plane_region("bedBottom", section.z_low), "areaAverage", "p") +
        surface_value("pBedTop", plane_region("bedTop", section.z_high), "areaAverage", "p") +
        surface_value("flowRate", patch_region("outlet"), "sum", "phi") +
        forces("forceWalls", "\"(.*wall)\"", p.density_kg_m3) +
        (bed.size() > 0 ? forces("forceParticles", "particles", p.density_kg_m3) : std::string()) +
        forces("forceInlet", "inlet", p.density_kg_m3) + forces("forceOutlet", "outlet", p.density_kg_m3);
    write_text(tmp / "system/controlDict",
               dict("dictionary", "system", "controlDict", note,
                    fmt::format("application     simpleFoam;\nstartFrom       startTime;\nstartTime       0;\n"
                                "stopAt          endTime;\nendTime         {};\ndeltaT          1;\n"
                                "writeControl    timeStep;\nwriteInterval   {};\npurgeWrite      1;\n"
                                "writeFormat     {};\nwritePrecision  10;\nwriteCompression off;\n"
                                "timeFormat      general;\ntimePrecision   8;\nrunTimeModifiable false;\n\n"
                                "// Pressure (kinematic, p/rho) averaged over the inlet, the outlet and the bed section's\n"
                                "// planes z = {:.6g} and {:.6g} m; flow rate through the outlet (m3/s); forces (N) on the\n"
                                "// walls, the particles, the inlet and the outlet.\n"
                                "functions\n{{\n{}}}\n",
                                p.iterations, p.iterations, fmt_word, section.z_low, section.z_high, functions)));
    // Tetrahedra in narrow gaps are far from orthogonal: limited corrections, one
    // non-orthogonal corrector, and SIMPLEC, which converges these creeping flows fast.
    // Gradients: least squares on the polyhedral dual, with which the empty tube's pressure drop
    // converges to the exact one and with Gauss linear it does not; on tetrahedra least squares
    // does not help, so they keep Gauss linear (docs/defaults.md).
    const std::string grad = p.polyhedra ? "leastSquares" : "Gauss linear";
    write_text(tmp / "system/fvSchemes",
               dict("dictionary", "system", "fvSchemes", note,
                    "ddtSchemes\n{\n    default         steadyState;\n}\n\n" +
                    fmt::format("gradSchemes\n{{\n    default         {0};\n    grad(U)         cellLimited {0} 1;\n}}\n\n",
                                grad) +
                    "divSchemes\n{\n    default         none;\n    div(phi,U)      bounded Gauss linearUpwind grad(U);\n"
                    "    div((nuEff*dev2(T(grad(U))))) Gauss linear;\n}\n\n"
                    "laplacianSchemes\n{\n    default         Gauss linear limited 0.5;\n}\n\n"
                    "interpolationSchemes\n{\n    default         linear;\n}\n\n"
                    "snGradSchemes\n{\n    default         limited 0.5;\n}\n"));
    write_text(tmp / "system/fvSolution",
               dict("dictionary", "system", "fvSolution", note,
                    fmt::format("solvers\n{{\n    p\n    {{\n        solver          GAMG;\n        smoother        GaussSeidel;\n"
                                "        tolerance       1e-8;\n        relTol          0.05;\n    }}\n"
                                "    U\n    {{\n        solver          smoothSolver;\n        smoother        symGaussSeidel;\n"
                                "        tolerance       1e-9;\n        relTol          0.1;\n    }}\n}}\n\n"
                                "SIMPLE\n{{\n    nNonOrthogonalCorrectors 1;\n    consistent      yes;\n"
                                "    residualControl\n    {{\n        p               {};\n        U               {};\n    }}\n}}\n\n"
                                "relaxationFactors\n{{\n    equations\n    {{\n        U               0.9;\n    }}\n"
                                "    fields\n    {{\n        p               1;\n    }}\n}}\n",
                                p.residual_p, *p.residual_u)));
    write_text(tmp / "system/decomposeParDict",
               dict("dictionary", "system", "decomposeParDict", note,
                    fmt::format("numberOfSubdomains {};\n\nmethod          {};\n\n"
                                "hierarchicalCoeffs\n{{\n    n               (1 1 {});\n    delta           0.001;\n"
                                "    order           xyz;\n}}\n",
                                p.processors, p.decomposition, p.processors)));
    write_text(tmp / "Allrun", allrun(p, section), true);
    write_text(tmp / "Allclean", kAllclean, true);
    write_text(tmp / "case.foam", "");  // for ParaView
    write_text(tmp / "bedforge/scene.toml", scene_toml);
    write_text(tmp / "bedforge/bed.csv", bed_csv);
    if (p.snappy) {
      // Background cells, refined `snappy_level` times at every surface; the fluid is the side
      // holding the point farthest from the bed's surfaces (also when a clip window leaves no
      // empty section).
      const double cell = p.snappy_cell_d * g.d_ref, pad = cell;
      const Eigen::Vector4d b = g.lateral_bounds + Eigen::Vector4d(-pad, -pad, pad, pad);
      const double z0 = g.inlet_z - pad, z1 = g.outlet_z + pad;
      auto cells = [&](double length) { return std::max(1, static_cast<int>(std::ceil(length / cell))); };
      // A hard link where the file system allows it: a bed's surface can take gigabytes, and a
      // surface made anew replaces the run's file, not the case's.
      fs::create_directories(tmp / "constant/triSurface");
      std::error_code linked;
      fs::create_hard_link(fluid_stl, tmp / "constant/triSurface/fluid.stl", linked);
      if (linked) fs::copy_file(fluid_stl, tmp / "constant/triSurface/fluid.stl");
      write_text(tmp / "system/blockMeshDict",
                 dict("dictionary", "system", "blockMeshDict", note,
                      fmt::format("convertToMeters 1;\n\nvertices\n(\n    ({0} {1} {4}) ({2} {1} {4}) ({2} {3} {4}) ({0} {3} {4})\n"
                                  "    ({0} {1} {5}) ({2} {1} {5}) ({2} {3} {5}) ({0} {3} {5})\n);\n\n"
                                  "blocks\n(\n    hex (0 1 2 3 4 5 6 7) ({6} {7} {8}) simpleGrading (1 1 1)\n);\n\n"
                                  "boundary\n(\n    background\n    {{\n        type patch;\n        faces\n        (\n"
                                  "            (0 3 2 1) (4 5 6 7) (0 1 5 4) (1 2 6 5) (2 3 7 6) (3 0 4 7)\n        );\n    }}\n);\n",
                                  b[0], b[1], b[2], b[3], z0, z1, cells(b[2] - b[0]), cells(b[3] - b[1]), cells(z1 - z0))));
      write_text(tmp / "system/surfaceFeatureExtractDict",
                 dict("dictionary", "system", "surfaceFeatureExtractDict", note,
                      "fluid.stl\n{\n    extractionMethod    extractFromSurface;\n"
                      "    extractFromSurfaceCoeffs\n    {\n        includedAngle   150;\n    }\n"
                      "    writeObj            no;\n}\n"));
      const Eigen::Vector3d inside = fluid_point(bed, g);
      std::string regions, levels;
      for (const std::string& name : patches) {
        const std::string type = meshing::patch_type(name);
        regions += fmt::format("            {0} {{ name {0}; }}\n", name);
        levels += fmt::format("                {0} {{ level ({2} {2}); patchInfo {{ type {1}; }} }}\n", name, type,
                              type == "wall" ? p.snappy_level : 0);
      }
      write_text(tmp / "system/snappyHexMeshDict",
                 dict("dictionary", "system", "snappyHexMeshDict", note,
                      fmt::format("castellatedMesh true;\nsnap            true;\naddLayers       false;\n\n"
                                  "geometry\n{{\n    fluid.stl\n    {{\n        type triSurfaceMesh;\n        name fluid;\n"
                                  "        regions\n        {{\n{}        }}\n    }}\n}}\n\n"
                                  "castellatedMeshControls\n{{\n    maxLocalCells   20000000;\n    maxGlobalCells  200000000;\n"
                                  "    minRefinementCells 0;\n    maxLoadUnbalance 0.1;\n    nCellsBetweenLevels 2;\n"
                                  "    features ( {{ file \"fluid.eMesh\"; level {}; }} );\n"
                                  "    refinementSurfaces\n    {{\n        fluid\n        {{\n            level (0 0);\n"
                                  "            regions\n            {{\n{}            }}\n        }}\n    }}\n"
                                  "    resolveFeatureAngle 30;\n    refinementRegions {{}}\n"
                                  "    locationInMesh ({:.9g} {:.9g} {:.9g});\n    allowFreeStandingZoneFaces true;\n}}\n\n"
                                  "snapControls\n{{\n    nSmoothPatch 3;\n    tolerance 2.0;\n    nSolveIter 30;\n    nRelaxIter 5;\n"
                                  "    nFeatureSnapIter 10;\n    implicitFeatureSnap false;\n    explicitFeatureSnap true;\n"
                                  "    multiRegionFeatureSnap false;\n}}\n\n"
                                  "addLayersControls\n{{\n    relativeSizes true;\n    layers {{}}\n    expansionRatio 1.0;\n"
                                  "    finalLayerThickness 0.3;\n    minThickness 0.1;\n    nGrow 0;\n    featureAngle 60;\n"
                                  "    nRelaxIter 3;\n    nSmoothSurfaceNormals 1;\n    nSmoothNormals 3;\n    nSmoothThickness 10;\n"
                                  "    maxFaceThicknessRatio 0.5;\n    maxThicknessToMedialRatio 0.3;\n    minMedialAxisAngle 90;\n"
                                  "    nBufferCellsNoExtrude 0;\n    nLayerIter 50;\n}}\n\n"
                                  "meshQualityControls\n{{\n    #includeEtc \"caseDicts/meshQualityDict\"\n    nSmoothScale 4;\n    errorReduction 0.75;\n}}\n\n"
                                  "mergeTolerance 1e-6;\n",
                                  regions, p.snappy_level, levels, inside.x(), inside.y(), inside.z())));
    }
    fs::remove_all(case_dir);  // the old case goes only once the new one is complete
    fs::rename(tmp, case_dir);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
  std::optional<double> fluid_volume;
  if (geometry) fluid_volume = std::accumulate(geometry->volumes.begin(), geometry->volumes.end(), 0.0);
  CaseInfo info{case_dir, p, u, nu, cells, section, g.aspect_ratio,
                g.cross_section_area, g.d_ref, fluid_volume, std::nullopt, std::nullopt};
  info.particles = bed.size() > 0;
  if (!info.particles && !p.slip_walls)
    info.exact_pressure_gradient_pa_m = analysis::laminar_duct_gradient(*bed.container, p.viscosity_pa_s, u);
  // Zick & Homsy's drag is Stokes flow's; at Re_p <= 0.01 inertia's share of the momentum balance
  // is at most 1 %, and in an array symmetric fore and aft its effect on the drag goes as Re_p^2.
  if (info.particles && spheres_as_packed && p.slip_walls && p.reynolds <= 0.01)
    info.exact_pressure_gradient_pa_m =
        analysis::simple_cubic_column_gradient(bed, p.viscosity_pa_s, u, section.z_low, section.z_high);
  return info;
}

namespace {

// The data rows of a function object's output file `file` (comment lines left out), its
// vectors' parentheses turned into spaces so that every number reads as a column.
std::vector<std::string> output_rows(const fs::path& case_dir, const std::string& name, const std::string& file) {
  const fs::path path = case_dir / "postProcessing" / name / "0" / file;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("the solver wrote no " + path.string());
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), '(', ' ');
    std::replace(line.begin(), line.end(), ')', ' ');
    rows.push_back(std::move(line));
  }
  if (rows.empty()) throw std::runtime_error("no value in " + path.string());
  return rows;
}

// The values (second column) of a surfaceFieldValue object's output, one per iteration.
std::vector<double> series(const fs::path& case_dir, const std::string& name) {
  std::vector<double> v;
  for (const std::string& line : output_rows(case_dir, name, "surfaceFieldValue.dat")) {
    std::istringstream row(line);
    double t = 0.0, x = 0.0;
    if (row >> t >> x) v.push_back(x);
  }
  if (v.empty()) throw std::runtime_error(fmt::format("no value in {}'s output", name));
  return v;
}

// The last force along z (N) in a forces object's output, in all and its viscous part.
struct ForceZ {
  double total = 0.0, viscous = 0.0;
};
ForceZ last_force_z(const fs::path& case_dir, const std::string& name) {
  std::istringstream row(output_rows(case_dir, name, "force.dat").back());  // time, total, pressure, viscous
  double t = 0.0, total[3], pressure[3], viscous[3];
  if (!(row >> t >> total[0] >> total[1] >> total[2] >> pressure[0] >> pressure[1] >> pressure[2] >> viscous[0] >>
        viscous[1] >> viscous[2]))
    throw std::runtime_error(fmt::format("no force in {}'s output", name));
  return {total[2], viscous[2]};
}

// One SIMPLE iteration of a simpleFoam log: its `Time = N`, the initial residuals (the largest
// of U's components, p's first solve) and the ExecutionTime at its end.
struct Iteration {
  long step = 0;
  double res_u = 0.0, res_p = 0.0, time_s = 0.0;
  bool p_seen = false;
};

// The iterations of a solver log, in order; `converged` is set when SIMPLE says so. Text before
// the first `Time =` (or a log's tail cut mid-iteration) starts no iteration.
std::vector<Iteration> read_iterations(std::istream& log, bool* converged = nullptr) {
  std::vector<Iteration> its;
  std::string line;
  while (std::getline(log, line)) {
    if (line.rfind("Time = ", 0) == 0) its.push_back({std::atol(line.c_str() + 7)});
    if (converged && line.find("SIMPLE solution converged") != std::string::npos) *converged = true;
    if (its.empty()) continue;
    Iteration& it = its.back();
    if (line.rfind("ExecutionTime = ", 0) == 0) it.time_s = std::atof(line.c_str() + 16);
    const auto at = line.find("Initial residual = ");
    if (at == std::string::npos) continue;
    const double r = std::atof(line.c_str() + at + 19);
    if (line.find("Solving for U") != std::string::npos) it.res_u = std::max(it.res_u, r);
    if (line.find("Solving for p,") != std::string::npos && !it.p_seen) it.res_p = r, it.p_seen = true;
  }
  return its;
}

// The last finished iteration of a log being written (step 0 before there is one). Only the
// log's tail is read, so polling a long run stays cheap.
Iteration last_iteration(const fs::path& log_path) {
  std::ifstream log(log_path, std::ios::binary | std::ios::ate);
  if (!log) return {};
  const std::streamoff size = log.tellg(), tail = std::min<std::streamoff>(size, 1 << 16);
  std::string text(static_cast<std::size_t>(tail), '\0');
  log.seekg(size - tail);
  log.read(text.data(), tail);
  std::istringstream in(text);
  const std::vector<Iteration> its = read_iterations(in);
  for (auto it = its.rbegin(); it != its.rend(); ++it)
    if (it->time_s > 0.0) return *it;  // ExecutionTime closes an iteration
  return {};
}

// Allrun's steps as GNU time logged them in log.time ("name seconds kB" per step; a failed
// step's extra line, and a machine without GNU time, give none).
std::vector<FlowResult::Step> allrun_steps(const fs::path& case_dir) {
  std::vector<FlowResult::Step> steps;
  std::ifstream in(case_dir / "log.time");
  for (std::string line; std::getline(in, line);) {
    std::istringstream row(line);
    FlowResult::Step s;
    double kb = 0.0;
    std::string rest;
    if (!(row >> s.name >> s.time_s >> kb) || row >> rest) continue;
    s.peak_memory_mb = kb / 1024.0;
    steps.push_back(s);
  }
  return steps;
}

// What Allrun's checkMesh printed: the cells, their total volume, and the faces of each patch
// (a patch left without faces anywhere is not listed). cells < 0: no checkMesh ran.
struct CheckMeshLog {
  long cells = -1;
  std::optional<double> volume_m3;
  std::map<std::string, long> patch_faces;
};
CheckMeshLog read_check_mesh_log(const fs::path& path) {
  CheckMeshLog out;
  std::ifstream in(path);
  bool in_patch_table = false;
  for (std::string line; std::getline(in, line);) {
    if (const auto at = line.find("cells:"); at != std::string::npos) out.cells = std::atol(line.c_str() + at + 6);
    if (const auto at = line.find("Total volume = "); at != std::string::npos) out.volume_m3 = std::atof(line.c_str() + at + 15);
    if (line.find("Patch") != std::string::npos && line.find("Faces") != std::string::npos) {
      in_patch_table = true;
      continue;
    }
    std::istringstream row(line);
    std::string name;
    long faces = 0;
    if (in_patch_table && row >> name >> faces)
      out.patch_faces[name] = faces;
    else
      in_patch_table = false;
  }
  return out;
}

// snappyHexMesh keeps the cells connected to the point inside the fluid. Where its cells do not
// fit the throats between the spheres, that region can miss the inlet or the outlet, and the
// solver then fails on the patch it lost: say so, and what makes finer cells.
void refuse_lost_ends(const CheckMeshLog& check, const CaseInfo& c) {
  std::vector<std::string> lost;
  for (const char* end : {"inlet", "outlet"})
    if (const auto it = check.patch_faces.find(end); it == check.patch_faces.end() || it->second == 0) lost.push_back(end);
  if (check.cells < 0 || lost.empty()) return;
  const std::string kept = check.volume_m3 && c.surface_volume_m3
                               ? fmt::format(" and hold {:.1f} % of the surface's fluid volume",
                                             100.0 * *check.volume_m3 / *c.surface_volume_m3)
                               : std::string();
  throw ConvergenceError(fmt::format(
      "snappyHexMesh's cells have no {0} faces{1}: the region they keep, around the point inside the fluid, does not "
      "reach the {0}, as happens where cells of {2:.3g} d at the surfaces (case.snappy_cell_d = {3}, "
      "case.snappy_level = {4}) do not fit the bed's narrowest throats; allowed: a smaller case.snappy_cell_d, a "
      "larger case.snappy_level, or gmsh's cells (case.mesher = \"gmsh\")",
      fmt::join(lost, " or "), kept, c.params.snappy_cell_d / std::pow(2.0, c.params.snappy_level),
      c.params.snappy_cell_d, c.params.snappy_level));
}

// The last line of a log that is not blank (Allrun's last words: which step failed).
std::string last_line(const fs::path& path) {
  std::ifstream in(path);
  std::string last;
  for (std::string line; std::getline(in, line);)
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

}  // namespace

std::string missing_openfoam_program(int processors) {
  std::vector<std::string> programs = {"simpleFoam", "checkMesh"};
  if (processors > 1) programs.insert(programs.end(), {"decomposePar", "reconstructPar", "mpirun"});
  const char* path = std::getenv("PATH");
  for (const std::string& program : programs) {
    bool found = false;
    std::istringstream dirs(path ? path : "");
    for (std::string d; !found && std::getline(dirs, d, ':');)
      found = !d.empty() && ::access((fs::path(d) / program).c_str(), X_OK) == 0;
    if (!found) return program;
  }
  return {};
}

FlowResult run_case(const CaseInfo& c, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path& case_dir = c.directory;
  const int np = c.params.processors;
  const bool snappy = c.params.snappy_cells;
  const std::string cmd = fmt::format("'{}/Allrun' -np {} > '{}/log.Allrun' 2>&1", case_dir.string(), np,
                                      case_dir.string());
  // Allrun in the background; meanwhile the solver's log tells how far it is. The ETA assumes
  // the residuals keep falling geometrically to their targets, and follows the one furthest
  // from its target.
  auto run = std::async(std::launch::async, [&cmd] { return std::system(cmd.c_str()); });
  const double target_p = c.params.residual_p, target_u = c.params.residual_u.value();
  double start_p = 0.0, start_u = 0.0;
  while (run.wait_for(std::chrono::milliseconds(500)) != std::future_status::ready) {
    const Iteration now = last_iteration(case_dir / "log.simpleFoam");
    if (now.step == 0 || now.res_p <= 0.0 || now.res_u <= 0.0) {
      progress.update(snappy ? "snappyHexMesh, then simpleFoam" : "preparing simpleFoam");
      continue;
    }
    if (start_p == 0.0) start_p = std::max(now.res_p, 10.0 * target_p), start_u = std::max(now.res_u, 10.0 * target_u);
    const double done = std::min(std::log(start_p / now.res_p) / std::log(start_p / target_p),
                                 std::log(start_u / now.res_u) / std::log(start_u / target_u));
    progress.update(fmt::format("simpleFoam iteration {}, residuals U {:.1e} p {:.1e} (targets {:.0e}, {:.0e})",
                                now.step, now.res_u, now.res_p, target_u, target_p),
                    std::clamp(done, 0.0, 1.0));
  }
  progress.finish();
  const CheckMeshLog check = read_check_mesh_log(case_dir / "log.checkMesh");
  if (run.get() != 0) {
    if (snappy) refuse_lost_ends(check, c);
    throw std::runtime_error(fmt::format("the OpenFOAM run failed ({}); see {}/log.Allrun and the logs next to it",
                                         last_line(case_dir / "log.Allrun"), case_dir.string()));
  }
  const double time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Convergence: SIMPLE's own message and, per iteration, the initial residuals and the time.
  std::ifstream log(case_dir / "log.simpleFoam");
  bool converged = false;
  const std::vector<Iteration> its = read_iterations(log, &converged);
  if (its.empty()) throw std::runtime_error(fmt::format("{}/log.simpleFoam holds no iteration", case_dir.string()));
  const long iterations = static_cast<long>(its.size());
  const double res_u = its.back().res_u, res_p = its.back().res_p;
  // Walls the flow slips along are mirror planes: the correlation's bed is then unbounded.
  const double a = c.params.slip_walls ? std::numeric_limits<double>::infinity() : c.aspect_ratio;
  const double rho = c.params.density_kg_m3, u = c.velocity_m_s, d = c.d_ref_m;
  const double zl = c.section.z_low, zh = c.section.z_high, re = c.params.reynolds;
  const std::vector<double> bottom = series(case_dir, "pBedBottom"), top = series(case_dir, "pBedTop");
  const std::size_t n = std::min(bottom.size(), top.size());
  auto bed_gradient = [&](std::size_t k) { return rho * (bottom[k] - top[k]) / (zh - zl); };
  const double gradient = bed_gradient(n - 1);
  // Convergence of the quantity itself: its change over the last tenth of the iterations.
  const double change = std::abs(gradient - bed_gradient(n - 1 - (n - 1) / 10)) / std::abs(gradient);
  const double overall = rho * (series(case_dir, "pInlet").back() - series(case_dir, "pOutlet").back());
  const double flow = series(case_dir, "flowRate").back();
  FlowResult r;
  r.mesher = snappy ? "snappyHexMesh" : c.params.polyhedra ? "gmsh polyhedral dual" : "gmsh tetrahedra";
  r.solved_cells = snappy || c.params.polyhedra ? -1 : c.cells;
  r.steps = allrun_steps(case_dir);
  if (snappy || c.params.polyhedra) {  // the cells Allrun made, as its checkMesh counted them
    r.solved_cells = check.cells;
    r.solved_volume_m3 = check.volume_m3;
    if (snappy && check.volume_m3 && c.surface_volume_m3) r.volume_lost = 1.0 - *check.volume_m3 / *c.surface_volume_m3;
  }
  // Convergence history: the residuals and the bed's pressure gradient against the solver's time.
  nlohmann::json history = nlohmann::json::array();
  for (std::size_t k = 0; k < its.size(); ++k) {
    nlohmann::json point = {{"iteration", k + 1}, {"time_s", its[k].time_s}, {"residual_U", its[k].res_u},
                            {"residual_p", its[k].res_p}};
    if (k < n) point["pressure_gradient_bed_pa_m"] = bed_gradient(k);
    history.push_back(std::move(point));
  }
  r.time_s = time;
  r.solver_peak_memory_mb = children_peak_memory_mb();
  r.iterations = iterations;
  r.history = thin_history(history);
  r.converged = converged;
  r.residual_u = res_u;
  r.residual_p = res_p;
  r.pressure_gradient_bed_pa_m = gradient;
  r.pressure_gradient_change_last_tenth = change;
  r.pressure_drop_inlet_outlet_pa = overall;
  r.flow_rate_m3_s = flow;
  r.flow_rate_relative_error = flow / (u * c.inlet_area_m2) - 1.0;
  const ForceZ walls = last_force_z(case_dir, "forceWalls");
  const ForceZ particles = c.particles ? last_force_z(case_dir, "forceParticles") : ForceZ{};
  r.drag_walls_n = walls.total, r.drag_walls_viscous_n = walls.viscous;
  r.drag_particles_n = particles.total, r.drag_particles_viscous_n = particles.viscous;
  r.push_inlet_outlet_n = -(last_force_z(case_dir, "forceInlet").total + last_force_z(case_dir, "forceOutlet").total);
  const double drag = r.drag_walls_n + r.drag_particles_n;
  r.wall_share_of_drag = r.drag_walls_n / drag;
  r.force_balance_relative_error = drag / r.push_inlet_outlet_n - 1.0;
  if (c.exact_pressure_gradient_pa_m) {
    r.exact_pa_m = c.exact_pressure_gradient_pa_m;
    r.relative_error_to_exact = gradient / *r.exact_pa_m - 1.0;
    return r;
  }
  if (const std::optional<double> eps = c.section.void_fraction) {
    r.eisfeld_schnitzlein_pa_m = analysis::pressure_gradient(analysis::eisfeld_schnitzlein_f(re, *eps, a), *eps, rho, u, d);
    r.ratio_to_eisfeld_schnitzlein = gradient / *r.eisfeld_schnitzlein_pa_m;
    r.void_fraction_section = eps;
  }
  const double eps_bed = c.section.void_fraction_bed;
  r.eisfeld_schnitzlein_bed_pa_m =
      analysis::pressure_gradient(analysis::eisfeld_schnitzlein_f(re, eps_bed, a), eps_bed, rho, u, d);
  r.ratio_to_eisfeld_schnitzlein_bed = gradient / r.eisfeld_schnitzlein_bed_pa_m;
  r.void_fraction_section_bed = eps_bed;
  r.wall_share_of_drag_eisfeld_schnitzlein = analysis::wall_wetted_area_share(eps_bed, a);
  return r;
}

}  // namespace bedforge::cases
