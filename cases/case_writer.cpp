#include "cases/case_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include "analysis/laminar_duct.hpp"
#include "analysis/pressure_drop.hpp"
#include "analysis/stokes_arrays.hpp"
#include "analysis/void_fraction.hpp"
#include "cases/drag_regions.hpp"
#include "cases/poly_mesh_io.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "meshing/volume/cyclic_patches.hpp"
#include "meshing/volume/dual_mesh.hpp"
#include "meshing/volume/flat_ears.hpp"
#include "meshing/volume/processor_patches.hpp"

namespace bedforge::cases {

namespace fs = std::filesystem;

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
  g.periodic = c.axial_period() > 0.0;
  g.bed_bottom = empty || g.periodic ? g.inlet_z : 0.0;
  g.bed_top = empty || g.periodic ? g.outlet_z : bed_height(bed);
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

KnownBound KnownBound::from_json(const nlohmann::json& j) {
  const auto side = j.at("side").get<std::string>();
  if (side != "below" && side != "above")
    throw std::runtime_error(fmt::format("a bound's side is \"{}\"; allowed: \"below\", \"above\"", side));
  return {j.at("pa_m").get<double>(), side == "below"};
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
          {"exact_pressure_gradient_pa_m", exact_pressure_gradient_pa_m ? nlohmann::json(*exact_pressure_gradient_pa_m) : nullptr},
          {"bound", bound ? bound->to_json() : nlohmann::json()},
          {"periodic_mean_velocity_m_s", mean_velocity_m_s ? nlohmann::json(*mean_velocity_m_s) : nullptr},
          {"walls", walls},
          {"stokes_array", stokes_array ? nlohmann::json{{"solid_fraction", stokes_array->solid_fraction},
                                                         {"diameter_m", stokes_array->diameter_m},
                                                         {"van_der_hoef_pa_m", stokes_array->pa_m}}
                                        : nlohmann::json()},
          {"stokes_array_not_compared",
           stokes_array_not_compared.empty() ? nlohmann::json() : nlohmann::json(stokes_array_not_compared)},
          {"polyhedra_quality", polyhedra_quality ? polyhedra_quality->to_json(d_ref_m) : nullptr}};
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
// (walls that slip); `.*wall` matches wall and inner_wall, `.*wall_ends` their parts beyond the
// section and `particles.*` the particles' patches split by gap (drag_regions.hpp). The
// constraint types cover processor patches, so the fields serve snappyHexMesh's cells as they
// come, decomposed.
std::string boundary_field(const std::string& inlet, const std::string& outlet, const std::string& walls,
                           const std::string& particles = {}) {
  const std::string solids =
      particles.empty()
          ? fmt::format("    \"(.*wall|.*wall_ends|particles.*)\"\n    {{\n{}    }}\n", walls)
          : fmt::format("    \"(.*wall|.*wall_ends)\"\n    {{\n{}    }}\n"
                        "    \"particles.*\"\n    {{\n{}    }}\n",
                        walls, particles);
  return fmt::format("boundaryField\n{{\n    #includeEtc \"caseDicts/setConstraintTypes\"\n"
                     "    inlet\n    {{\n{}    }}\n    outlet\n    {{\n{}    }}\n{}}}\n",
                     inlet, outlet, solids);
}

// A periodic section's inlet and outlet: one cyclic pair.
const char* kCyclic = "        type            cyclic;\n";

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
std::string allrun(const CaseParams& p, const BedSection& section, bool periodic) {
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
       "np=1\npieces=0\n" + std::string(p.snappy_cells ? "snappy=1\n" : "snappy=0\n") +
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
       "subdomains() {\n"
       "    sed -i -e \"s/^numberOfSubdomains .*/numberOfSubdomains $np;/\" \\\n"
       "        -e \"s/^    n .*/    n               (1 1 $np);/\" system/decomposeParDict\n"
       "}\n"
       "decompose() {\n"
       "    subdomains\n"
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
  if (!p.snappy_cells)
    s += "# A case whose pieces `bedforge piece` wrote (processor*/bedforge_piece.json, one rank each) is\n"
         "# decomposed already: its processes are its pieces, with no decomposePar; its results stay in\n"
         "# processor*/ (reconstructParMesh -constant, then reconstructPar, gather them).\n"
         "[ \"$snappy\" = 0 ] && pieces=$(ls processor*/bedforge_piece.json 2>/dev/null | wc -l)\n"
         "[ \"$pieces\" -gt 1 ] && np=$pieces && subdomains\n";
  if (p.polyhedra && !p.snappy_cells)
    s += "# constant/polyMesh holds the dual polyhedra of gmsh's tetrahedra, as `polyDualMesh 80` makes them:\n"
         "# an empty tube's pressure drop converges to the exact one on the dual, not on the tetrahedra.\n"
         "if [ \"$snappy\" = 0 ]; then\n"
         "    if [ \"$pieces\" -gt 1 ]; then parallel checkMesh; else run checkMesh; fi\n"
         "fi\n";
  else if (!p.snappy_cells)
    s += "[ \"$pieces\" -gt 1 ] && parallel checkMesh\n";
  s += "# Past about a million cells per process the solver's temporary fields outgrow glibc's 32 MB\n"
       "# limit for heap blocks: each was mapped afresh and cleared page by page on every use, which\n"
       "# made an iteration ten times slower. Kept in the heap, they are reused (a larger peak); the\n"
       "# setting holds for every step from here on.\n"
       "export MALLOC_MMAP_MAX_=0 MALLOC_TRIM_THRESHOLD_=1000000000000\n"
       "if [ \"$pieces\" -gt 1 ]; then\n"
       "    parallel simpleFoam\n"
       "elif [ \"$np\" -gt 1 ]; then\n"
       "    [ \"$snappy\" = 1 ] || decompose\n"
       "    parallel simpleFoam\n"
       "    [ \"$snappy\" = 1 ] || run reconstructPar -latestTime\n"
       "else\n"
       "    run simpleFoam\n"
       "fi\n";
  if (periodic) {
    // The result: the mean pressure gradient meanVelocityForce applied at the last iteration.
    s += fmt::format(
        "# The bed's pressure gradient: the one meanVelocityForce applied at the last iteration to hold the\n"
        "# cells' mean velocity (kinematic, times rho = {0:.12g} kg/m3), at the flow rate solved; bedforge\n"
        "# scales it to the flow rate set (postProcessing/flowRate).\n"
        "awk -v rho={0:.12g} '/pressure gradient = / {{ g = $NF; n++ }}\n"
        "    END {{\n"
        "        if (!n) {{ print \"no pressure gradient in log.simpleFoam\" > \"/dev/stderr\"; exit 1 }}\n"
        "        printf \"dp/L over the periodic section: %.6g Pa/m\\n\", rho * g\n"
        "    }}' log.simpleFoam || exit 1\n",
        p.density_kg_m3);
    return s;
  }
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


// 0/U and 0/p, and the fluid's properties: laminar flow of kinematic viscosity `nu` (m2/s) up
// from the inlet at the superficial velocity `u` (m/s), out at zero pressure; walls and
// particles without slip unless the walls slip. An inlet that cuts through the bed (a clip
// window's) holds only the fluid's part of the section: there the flow rate `inlet_flow` (m3/s)
// is set instead (flowRateInletVelocity), else the superficial velocity would fall by the
// plane's void fraction.
void write_fields(const fs::path& tmp, const CaseParams& p, double u, double nu, double d_ref,
                  std::optional<double> ubar, std::optional<double> inlet_flow, const std::string& note) {
  auto field_dict = [&](const std::string& cls, const std::string& object, const std::string& body) {
    return foam_header(cls, "0", object, note, false) + body;
  };
  write_text(tmp / "0/U",
             field_dict("volVectorField", "U",
                        fmt::format("// superficial velocity {:.6g} m/s: Re_p = {} with d = {:.6g} m, nu = {:.6g} m2/s\n"
                                    "dimensions      [0 1 -1 0 0 0 0];\n\ninternalField   uniform (0 0 {:.12g});\n\n",
                                    u, p.reynolds, d_ref, nu, ubar.value_or(u)) +
                            boundary_field(ubar          ? kCyclic
                                           : inlet_flow ? fmt::format("        type            flowRateInletVelocity;\n"
                                                                      "        volumetricFlowRate constant {:.12g};  // the "
                                                                      "superficial velocity times the section\n"
                                                                      "        value           uniform (0 0 {:.12g});\n",
                                                                      *inlet_flow, u)
                                                        : fmt::format("        type            fixedValue;\n"
                                                                      "        value           uniform (0 0 {:.12g});\n",
                                                                      u),
                                           ubar ? kCyclic
                                                : "        type            inletOutlet;\n"
                                                  "        inletValue      uniform (0 0 0);\n"
                                                  "        value           uniform (0 0 0);\n",
                                           p.slip_walls ? "        type            slip;\n" : "        type            noSlip;\n",
                                           p.slip_walls ? "        type            noSlip;\n" : "")));
  write_text(tmp / "0/p", field_dict("volScalarField", "p",
                                     "// kinematic pressure p/rho\ndimensions      [0 2 -2 0 0 0 0];\n\n"
                                     "internalField   uniform 0;\n\n" +
                                         boundary_field(ubar ? kCyclic : "        type            zeroGradient;\n",
                                                        ubar ? kCyclic
                                                             : "        type            fixedValue;\n"
                                                               "        value           uniform 0;\n",
                                                        "        type            zeroGradient;\n")));
  // A periodic section is driven by the mean pressure gradient that holds the fluid's volume-mean
  // velocity at ubar, the superficial velocity over the meshed void fraction.
  if (ubar)
    write_text(tmp / "system/fvOptions",
               dict("dictionary", "system", "fvOptions", note,
                    fmt::format("momentumSource\n{{\n    type            meanVelocityForce;\n"
                                "    selectionMode   all;\n    fields          (U);\n"
                                "    Ubar            (0 0 {:.12g});  // superficial {:.6g} m/s over the cells' void fraction\n}}\n",
                                *ubar, u)));
  write_text(tmp / "constant/transportProperties",
             dict("dictionary", "constant", "transportProperties", note,
                  fmt::format("transportModel  Newtonian;\n\nnu              {:.12g};  // mu/rho = {} / {}\n", nu,
                              p.viscosity_pa_s, p.density_kg_m3)));
  write_text(tmp / "constant/turbulenceProperties",
             dict("dictionary", "constant", "turbulenceProperties", note, "simulationType  laminar;\n"));
}

// controlDict: the iteration cap and, as function objects, the pressure averaged over the inlet,
// the outlet and the section's planes, the flow rate and the forces on every solid patch.
void write_control_dict(const fs::path& tmp, const CaseParams& p, const BedSection& section, bool particles,
                        bool walls, bool periodic, const std::vector<GapBand>& gap_bands, long wall_faces_beyond,
                        const std::string& note) {
  const std::string fmt_word = p.binary ? "binary" : "ascii";
  // A periodic section's pressure is periodic: the gradient is meanVelocityForce's, and the
  // cyclic patches carry no force.
  std::string gap_forces;
  for (const GapBand& b : gap_bands)
    if (b.faces > 0) gap_forces += forces(b.force_object(), b.patch(), p.density_kg_m3);
  const std::string functions =
      (periodic ? std::string()
                : surface_value("pInlet", patch_region("inlet"), "areaAverage", "p") +
                      surface_value("pOutlet", patch_region("outlet"), "areaAverage", "p") +
                      surface_value("pBedBottom", plane_region("bedBottom", section.z_low), "areaAverage", "p") +
                      surface_value("pBedTop", plane_region("bedTop", section.z_high), "areaAverage", "p")) +
      surface_value("flowRate", patch_region("outlet"), "sum", "phi") +
      // Without walls no patch matches, and OpenFOAM's forces then takes the particles again.
      (walls ? forces("forceWalls", "\"(.*wall|.*wall_ends)\"", p.density_kg_m3) : std::string()) +
      (wall_faces_beyond > 0 ? forces("forceWallsEnds", "\".*wall_ends\"", p.density_kg_m3) : std::string()) +
      (particles ? forces("forceParticles", "\"particles.*\"", p.density_kg_m3) : std::string()) +
      gap_forces +
      (periodic ? std::string()
                : forces("forceInlet", "inlet", p.density_kg_m3) + forces("forceOutlet", "outlet", p.density_kg_m3));
  // runTimeModifiable: run_case stops a diverging solve by setting stopAt to writeNow as it runs.
  write_text(tmp / "system/controlDict",
             dict("dictionary", "system", "controlDict", note,
                  fmt::format("application     simpleFoam;\nstartFrom       startTime;\nstartTime       0;\n"
                              "stopAt          endTime;\nendTime         {};\ndeltaT          1;\n"
                              "writeControl    timeStep;\nwriteInterval   {};\npurgeWrite      1;\n"
                              "writeFormat     {};\nwritePrecision  10;\nwriteCompression off;\n"
                              "timeFormat      general;\ntimePrecision   8;\nrunTimeModifiable true;\n\n"
                              "// Pressure (kinematic, p/rho) averaged over the inlet, the outlet and the bed section's\n"
                              "// planes z = {:.6g} and {:.6g} m; flow rate through the outlet (m3/s); forces (N) on the\n"
                              "// walls, the particles, the inlet and the outlet.\n"
                              "functions\n{{\n{}}}\n",
                              p.iterations, p.iterations, fmt_word, section.z_low, section.z_high, functions)));
}

// fvSchemes, fvSolution and decomposeParDict. Tetrahedra in narrow gaps are far from orthogonal:
// one non-orthogonal corrector, and SIMPLEC, which converges these creeping flows fast. On the
// polyhedral dual: least-squares gradients (the empty tube converges to the exact pressure drop;
// with Gauss linear it does not) and limited corrections. On tetrahedra the pressure carries a
// cell-to-cell noise, which gradients from the four face neighbours turn into a force (the tube
// +16 %): there gradients fit over the cells sharing a vertex, the correction is full, without
// which the Laplacian alone stays biased, and the flux of H/A is taken at the faces' centres
// (skewCorrected): linear interpolation gives it where the line of centres crosses the face, an
// error that grows with the shear and made that noise and a bias no refinement removed
// (docs/defaults.md).
void write_solver_settings(const fs::path& tmp, const CaseParams& p, bool periodic, const std::string& note) {
  const std::string grad = p.polyhedra ? "leastSquares" : "pointCellsLeastSquares",
                    correction = p.polyhedra ? "limited 0.5" : "corrected",
                    flux = p.polyhedra ? "" : "    flux(HbyA)      skewCorrected linear;\n";
  write_text(tmp / "system/fvSchemes",
             dict("dictionary", "system", "fvSchemes", note,
                  "ddtSchemes\n{\n    default         steadyState;\n}\n\n" +
                  fmt::format("gradSchemes\n{{\n    default         {0};\n    grad(U)         cellLimited {0} 1;\n}}\n\n",
                              grad) +
                  "divSchemes\n{\n    default         none;\n    div(phi,U)      bounded Gauss linearUpwind grad(U);\n"
                  "    div((nuEff*dev2(T(grad(U))))) Gauss linear;\n}\n\n" +
                  fmt::format("laplacianSchemes\n{{\n    default         Gauss linear {0};\n}}\n\n"
                              "interpolationSchemes\n{{\n    default         linear;\n{1}}}\n\n"
                              "snGradSchemes\n{{\n    default         {0};\n}}\n",
                              correction, flux)));
  write_text(tmp / "system/fvSolution",
             dict("dictionary", "system", "fvSolution", note,
                  fmt::format("solvers\n{{\n    p\n    {{\n        solver          GAMG;\n        smoother        GaussSeidel;\n"
                              "        tolerance       1e-8;\n        relTol          0.05;\n    }}\n"
                              "    U\n    {{\n        solver          smoothSolver;\n        smoother        symGaussSeidel;\n"
                              "        tolerance       1e-9;\n        relTol          0.1;\n    }}\n}}\n\n"
                              // Each iteration asks for grad(U) and grad(p) several times over an unchanged
                              // field; kept, they are computed once (the vertex fit's gradients are a third
                              // of an iteration's time on tetrahedra; the solution does not change).
                              "cache\n{{\n    grad(U);\n    grad(p);\n}}\n\n"
                              "SIMPLE\n{{\n    nNonOrthogonalCorrectors 1;\n    consistent      yes;\n{}"
                              "    // A hundredth of case.residual_p and residual_u: bedforge stops the solve before,\n"
                              "    // once those are reached and dp/L has settled (case.iteration_tolerance).\n"
                              "    residualControl\n    {{\n        p               {:g};\n        U               {:g};\n    }}\n}}\n\n"
                              "relaxationFactors\n{{\n    equations\n    {{\n        U               0.9;\n    }}\n"
                              "    fields\n    {{\n        p               1;\n    }}\n}}\n",
                              // With cyclic inlet and outlet no boundary fixes the pressure's level.
                              periodic ? "    pRefCell        0;\n    pRefValue       0;\n" : "",
                              *p.residual_p * kResidualControlShare, *p.residual_u * kResidualControlShare)));
  write_text(tmp / "system/decomposeParDict",
             dict("dictionary", "system", "decomposeParDict", note,
                  fmt::format("numberOfSubdomains {};\n\nmethod          {};\n\n"
                              "hierarchicalCoeffs\n{{\n    n               (1 1 {});\n    delta           0.001;\n"
                              "    order           xyz;\n}}\n{}",
                              p.processors, p.decomposition, p.processors,
                              // A cyclic pair's faces on one process: else each keeps none of the patch itself
                              // (they become processorCyclic faces) and the flow rate over it has no faces.
                              periodic ? "\nconstraints\n{\n    cyclics\n    {\n        type            preservePatches;\n"
                                         "        patches         (inlet outlet \"(x|y)_(min|max)\");\n    }\n}\n"
                                       : "")));
}

// snappyHexMesh's set-up for the fluid surface `fluid_stl` (ASCII STL, a solid per patch named in
// `patches`): the background blocks, the features, the refinement and the point inside.
void write_snappy_setup(const fs::path& tmp, const CaseParams& p, const CaseGeometry& g, const Bed& bed,
                        const std::vector<std::string>& patches, const fs::path& fluid_stl,
                        const std::string& note) {
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

}  // namespace

void refuse_existing_case(const fs::path& case_dir, bool overwrite) {
  if (!overwrite && fs::exists(case_dir))
    throw InputError(fmt::format("{} exists; remove it or pass --overwrite", case_dir.string()));
}

namespace {

template <class Mesh>
void write_piece(const fs::path& case_dir, int piece, const Mesh& mesh, bool binary, const std::string& note,
                 const nlohmann::json& report) {
  write_directory_atomically(case_dir / fmt::format("processor{}", piece), [&](const fs::path& tmp) {
    write_poly_mesh(tmp / "constant/polyMesh", mesh, binary, note);
    fs::copy(case_dir / "0", tmp / "0", fs::copy_options::recursive);
    write_text(tmp / "bedforge_piece.json", report.dump(2) + "\n");
    meshing::write_processor_faces(tmp / kProcessorFacesFile, meshing::processor_faces(mesh));
  });
}

}  // namespace

void write_case_piece(const fs::path& case_dir, int piece, const meshing::PolyMesh& mesh, bool binary,
                      const std::string& note, const nlohmann::json& report) {
  write_piece(case_dir, piece, mesh, binary, note, report);
}
void write_case_piece(const fs::path& case_dir, int piece, const meshing::PolyhedralMesh& mesh, bool binary,
                      const std::string& note, const nlohmann::json& report) {
  write_piece(case_dir, piece, mesh, binary, note, report);
}

fs::path set_pieces_aside(const fs::path& case_dir) {
  const fs::path aside = case_dir.parent_path() / ("." + case_dir.filename().string() + ".pieces-aside");
  fs::create_directories(aside);
  if (fs::is_directory(case_dir))
    for (const auto& entry : fs::directory_iterator(case_dir)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("processor", 0) == 0 || name == "piece_layers") {
        fs::remove_all(aside / name);
        fs::rename(entry.path(), aside / name);
      }
    }
  return aside;
}

void put_pieces_back(const fs::path& aside, const fs::path& case_dir, int pieces) {
  for (int k = 0; k < pieces; ++k)
    if (const fs::path from = aside / fmt::format("processor{}", k); fs::exists(from))
      fs::rename(from, case_dir / from.filename());
  if (fs::exists(aside / "piece_layers")) fs::rename(aside / "piece_layers", case_dir / "piece_layers");
  fs::remove_all(aside);  // pieces beyond the count
}

void set_known_answers(CaseInfo& info, const Bed& bed, const TreatedSolid& treated) {
  const CaseParams& p = info.params;
  const double u = info.velocity_m_s;
  const BedSection& section = info.section;
  const double sphere_scale = treated.sphere_scale;
  if (!info.particles && !p.slip_walls)
    info.exact_pressure_gradient_pa_m = analysis::laminar_duct_gradient(*bed.container, p.viscosity_pa_s, u);
  // Zick & Homsy's drag is Stokes flow's; at Re_p <= 0.01 inertia's share of the momentum balance
  // is at most 1 %, and in an array symmetric fore and aft its effect on the drag goes as Re_p^2.
  std::optional<double> lattice;  // the untreated bed's, when it is a simple cubic column or array
  if (info.particles && p.slip_walls && p.reynolds <= 0.01)
    lattice = analysis::simple_cubic_column_gradient(bed, p.viscosity_pa_s, u, section.z_low, section.z_high);
  if (!lattice && info.particles && !info.walls && p.reynolds <= 0.01)
    lattice = analysis::simple_cubic_array_gradient(bed, p.viscosity_pa_s, u);
  if (lattice && sphere_scale == 1.0) info.exact_pressure_gradient_pa_m = lattice;
  if (lattice && sphere_scale != 1.0 && treated.change != 0) info.bound = KnownBound{*lattice, treated.change > 0};
  // A random array with no wall, as van der Hoef et al. simulated it: equal spheres in a box
  // periodic on every side, Stokes flow (inertia's share at most 1 %, as above), at the spheres'
  // size and solid fraction as solved; not a lattice, whose answer is known.
  const bool random_array = info.particles && !lattice && !info.walls &&
                            bed.container->periodicity().lz > 0.0 && sphere_scale > 0.0 && p.reynolds <= 0.01;
  const bool equal = std::all_of(bed.diameters.begin(), bed.diameters.end(),
                                 [&bed](double x) { return x == bed.diameters[0]; });
  if (random_array && equal) {
    const double phi = (1.0 - section.void_fraction_bed) * sphere_scale * sphere_scale * sphere_scale;
    const double d = bed.diameters[0] * sphere_scale;
    info.stokes_array = CaseInfo::StokesArray{phi, d, analysis::van_der_hoef_gradient(phi, p.viscosity_pa_s, u, d)};
  } else if (random_array) {
    info.stokes_array_not_compared = "their fit is for equal spheres, and this bed's differ in size";
  }
}

CaseInfo write_case(const fs::path& case_dir, bool overwrite, const meshing::PolyMesh* mesh,
                    const std::vector<std::string>& patches, const CaseGeometry& g, const Bed& bed,
                    const CaseParams& given, const std::string& note, const std::string& scene_toml,
                    const std::string& bed_csv, const fs::path& fluid_stl, const TreatedSolid& treated) {
  refuse_existing_case(case_dir, overwrite);
  CaseParams p = given;
  // The residual targets: prism layers stall U's residual and keep the general targets otherwise;
  // a periodic section's driving gradient settles slowly and needs tighter ones (case_params.hpp).
  const bool prisms = mesh && meshing::has_prisms(*mesh);
  if (!p.residual_u) p.residual_u = prisms ? kResidualULayered : g.periodic ? kResidualPeriodic : kResidualU;
  if (!p.residual_p) p.residual_p = g.periodic && !prisms ? kResidualPeriodic : kResidualP;
  const double nu = p.viscosity_pa_s / p.density_kg_m3;
  const double u = p.reynolds * nu / g.d_ref;  // superficial velocity
  // On polyhedra the tetrahedra lose their flat ears first (slivers on the wall that no optimiser
  // pass removes, whose dual fails checkMesh): a copy, made only when there are some.
  const bool polyhedra = mesh && p.polyhedra && !p.snappy_cells;
  std::optional<meshing::PolyMesh> without_ears;
  const std::vector<int> ears = polyhedra ? meshing::flat_ears(*mesh) : std::vector<int>{};
  if (!ears.empty()) {
    without_ears = *mesh;
    meshing::cut_ears(*without_ears, ears);
    mesh = &*without_ears;
  }
  const std::optional<meshing::CellGeometry> geometry =
      mesh ? std::optional(meshing::cell_geometry(*mesh)) : std::nullopt;
  // A periodic section's bed section is its whole period, its void fraction the spheres' over it.
  BedSection section = bed_section(geometry ? &*geometry : nullptr, g, g.periodic ? 0.0 : p.section_exclude_d);
  section.void_fraction_bed =
      g.periodic ? 1.0 - solid_volume(bed) / (g.cross_section_area * bed.container->axial_period())
                 : analysis::void_fraction(bed, section.z_low, section.z_high);
  std::optional<double> fluid_volume;
  if (geometry) fluid_volume = std::accumulate(geometry->volumes.begin(), geometry->volumes.end(), 0.0);
  std::optional<double> ubar;
  if (g.periodic) {
    if (!mesh || p.snappy)
      throw InputError("a periodic section's case needs gmsh's cells; allowed: case.mesher \"gmsh\" without the "
                       "snappyHexMesh set-up");
    ubar = u * g.cross_section_area * (g.outlet_z - g.inlet_z) / *fluid_volume;
  }
  // A clip window's inlet plane cuts spheres: the flow rate is set, not the velocity over its fluid.
  bool inlet_in_bed = false;
  for (std::size_t i = 0; i < bed.size() && !g.periodic; ++i)
    inlet_in_bed = inlet_in_bed || std::abs(bed.centres[i].z() - g.inlet_z) < 0.5 * bed.diameters[i];
  const std::optional<double> inlet_flow = inlet_in_bed ? std::optional(u * g.cross_section_area) : std::nullopt;
  const bool walls = bed.container->wall_perimeter() > 0.0;  // a box periodic on every side has none
  long cells = mesh ? mesh->cells : 0;  // as written
  std::optional<meshing::JudgedQuality> polyhedra_quality;
  std::vector<GapBand> gap_bands;
  long wall_faces_beyond_section = 0;
  auto split_by_gap = [&](auto& written) {
    wall_faces_beyond_section = split_walls_at_section(written, section.z_low, section.z_high);
    return split_particles_by_gap(written, bed, g.d_ref, p.drag_by_gap_d, section.z_low, section.z_high);
  };
  write_directory_atomically(case_dir, [&](const fs::path& tmp) {
    // On polyhedra the case holds the dual of gmsh's cells, made here as `polyDualMesh 80` makes
    // it (which peaked at about 1 kB per tetrahedron).
    if (polyhedra) {
      meshing::PolyhedralMesh dual = meshing::dual_mesh(*mesh, geometry->centres, kDualFeatureAngleDeg);
      polyhedra_quality = meshing::check_polyhedra(dual, {}, nullptr, bed, g.d_ref, "the case's polyhedra",
                                                  case_dir.parent_path() /
                                                      fmt::format("bad_polyhedra_{}.vtk", case_dir.filename().string()));
      polyhedra_quality->ears_cut = static_cast<long>(ears.size());
      if (g.periodic) meshing::match_every_cyclic_pair(dual);
      if (!p.drag_by_gap_d.empty()) gap_bands = split_by_gap(dual);
      write_poly_mesh(tmp / "constant/polyMesh", dual, p.binary, note);
      cells = dual.cells;
    } else if (mesh && (g.periodic || !p.drag_by_gap_d.empty())) {  // a copy, changed
      meshing::PolyMesh changed = *mesh;
      if (g.periodic) meshing::match_every_cyclic_pair(changed);
      if (!p.drag_by_gap_d.empty()) gap_bands = split_by_gap(changed);
      write_poly_mesh(tmp / "constant/polyMesh", changed, p.binary, note);
    } else if (mesh) {
      write_poly_mesh(tmp / "constant/polyMesh", *mesh, p.binary, note);
    }
    write_fields(tmp, p, u, nu, g.d_ref, ubar, inlet_flow, note);
    write_control_dict(tmp, p, section, bed.size() > 0, walls, g.periodic, gap_bands, wall_faces_beyond_section,
                       note);
    write_solver_settings(tmp, p, g.periodic, note);
    write_text(tmp / "Allrun", allrun(p, section, g.periodic), true);
    write_text(tmp / "Allclean", kAllclean, true);
    write_text(tmp / "case.foam", "");  // for ParaView
    write_text(tmp / "bedforge/scene.toml", scene_toml);
    write_text(tmp / "bedforge/bed.csv", bed_csv);
    if (p.snappy) write_snappy_setup(tmp, p, g, bed, patches, fluid_stl, note);
  });  // the old case goes only once the new one is complete
  CaseInfo info{case_dir, p, u, nu, cells, section, g.aspect_ratio,
                g.cross_section_area, g.d_ref, fluid_volume, std::nullopt, std::nullopt};
  info.particles = bed.size() > 0;
  info.walls = walls;
  info.mean_velocity_m_s = ubar;
  info.polyhedra_quality = polyhedra_quality;
  info.gap_bands = std::move(gap_bands);
  info.wall_faces_beyond_section = wall_faces_beyond_section;
  set_known_answers(info, bed, treated);
  return info;
}

}  // namespace bedforge::cases
