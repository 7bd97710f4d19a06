#pragma once
#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bed.hpp"
#include "core/progress.hpp"
#include "core/scene_section.hpp"
#include "meshing/cell_quality.hpp"
#include "meshing/poly_mesh.hpp"

namespace bedforge::cases {

// SIMPLE's target for U's initial residual when [case] residual_u is unset.
inline constexpr double kResidualU = 1.0e-4;
inline constexpr double kResidualULayered = 1.0e-2;  // on cells with prism layers
// The meshes of a convergence study when the case is run and the scene names none.
inline constexpr int kStudyLevels = 3;
// Boundary edges sharper than this (deg; the inlet's and outlet's rims) stay edges of the dual.
inline constexpr double kDualFeatureAngleDeg = 80.0;

// The OpenFOAM case, scene section [case]: steady laminar incompressible flow (simpleFoam) up
// through the bed, inlet at the bottom.
struct CaseParams {
  double reynolds = 1.0;                // particle Reynolds number rho u d / mu, u superficial, d the reference diameter
  double density_kg_m3 = 1000.0;        // fluid density (water)
  double viscosity_pa_s = 1.0e-3;       // dynamic viscosity (water)
  int iterations = 3000;                // simpleFoam iteration cap (endTime)
  double residual_p = 1.0e-4;           // SIMPLE stops when the initial residuals fall below these (on
                                        // these tetrahedral meshes p plateaus near 5e-5 once dp has 4 digits)
  // Unset: kResidualU, or kResidualULayered on cells with prism layers, where U's residual
  // stalls near 3e-3 while the pressure drop has settled (docs/findings.md, 2026-11-26, night);
  // write_case sets it.
  std::optional<double> residual_u;
  int processors = 1;                   // subdomains in decomposeParDict; Allrun -np N overrides
  // hierarchical: slabs along the column (n = 1 1 N), few interface faces in a column; scotch:
  // graph partitioning, for OpenFOAM builds that have it (Debian's v1912 ships only a stub).
  std::string decomposition = "hierarchical";
  bool binary = true;                   // polyMesh and fields in binary, else ASCII
  // cells = "polyhedra": the case holds the dual polyhedra of gmsh's tetrahedra (as OpenFOAM's
  // polyDualMesh makes them, meshing/dual_mesh.hpp), on which an empty tube's pressure drop
  // converges to the exact one; "tetrahedra" solves on gmsh's cells, where it does not
  // (docs/defaults.md).
  bool polyhedra = true;
  // mesher = "snappy": snappyHexMesh makes the cells in Allrun from the fluid surface, on as
  // many processes as the run has, and no gmsh mesh is made: the route past one machine's memory.
  bool snappy_cells = false;
  bool snappy = false;                  // write the snappyHexMesh set-up (with gmsh's cells: used by Allrun -snappy)
  double snappy_cell_d = 0.25;          // snappyHexMesh background cell, in reference diameters
  int snappy_level = 2;                 // refinement levels at particles and walls
  // walls = "slip": the flow slips along the container's walls, mirror planes of the flow (a box
  // then stands for a slab of an unbounded bed, or a cell of an array); "no_slip" otherwise.
  bool slip_walls = false;
  double section_exclude_d = 0.5;       // bed section for the pressure drop: floor (or clip inlet) + this to bed top (or clip outlet) - this
  bool run = false;                     // run Allrun after writing and read the pressure drop back
  // [case.convergence]: the flow solved again on coarser meshes of the same bed, for the pressure
  // drop's discretisation error (Richardson extrapolation and the grid convergence index).
  struct Convergence {
    int levels = 0;        // meshes in all, the scene's own the finest; 0: no study, else 3-6 (a scene's
                           // default: kStudyLevels when the case is run on gmsh's cells)
    double ratio = 1.3;    // cell size ratio between successive levels (surface and volume together)
  } convergence;
};
CaseParams read_case_params(SceneSection& s);
nlohmann::json to_json(const CaseParams& p);

// What the case needs to know about the bed and its domain (m).
struct CaseGeometry {
  double d_ref = 0.0;          // reference (Sauter) diameter
  // D_h/d for the correlation, D_h = 4 A / P the hydraulic diameter: D for a cylinder. Eisfeld &
  // Schnitzlein fitted cylinders; their wall term A_w (Mehta & Hawley's wall area per bed
  // volume, 4 / D) is exact for any cross-section with D_h, B_w is carried over unproven.
  double aspect_ratio = 0.0;
  double cross_section_area = 0.0;
  Eigen::Vector4d lateral_bounds = Eigen::Vector4d::Zero();  // xmin, ymin, xmax, ymax of the cross-section
  double inlet_z = 0.0, outlet_z = 0.0;
  double bed_bottom = 0.0, bed_top = 0.0;  // the floor and the top sphere; an empty container's inlet and outlet
};

// The case geometry of a bed (m) and the points of its fluid domain (the volume mesh's or the
// fluid surface's): the inlet and outlet are their lowest and highest, the rest comes from the
// bed's container and spheres.
CaseGeometry case_geometry(const std::vector<Eigen::Vector3d>& points, const Bed& bed);

// A point of the fluid domain as far as it can find from every sphere, wall, inlet and outlet
// (m): snappyHexMesh keeps the cells connected to it. Searched on a lattice over the domain.
Eigen::Vector3d fluid_point(const Bed& bed, const CaseGeometry& g);

// Bed section over which the pressure drop is measured: its planes and its void fraction as
// meshed (cells with their centre between the planes over the container's volume between them),
// from the mesh's cell geometry.
struct BedSection {
  double z_low = 0.0, z_high = 0.0;
  // As meshed: the treated contacts and the facets included; unknown when snappyHexMesh makes
  // the cells.
  std::optional<double> void_fraction;
  double void_fraction_bed = 0.0;  // of the spheres as packed, exact (set by write_case)
};
// `cells` null: the planes only.
BedSection bed_section(const meshing::CellGeometry* cells, const CaseGeometry& g, double exclude_d);

// InputError when `case_dir` exists and `overwrite` is false (checked again by write_case;
// callers check first to refuse before the long stages).
void refuse_existing_case(const std::filesystem::path& case_dir, bool overwrite);

// A case as written: what running it and comparing its pressure drop need.
struct CaseInfo {
  std::filesystem::path directory;
  CaseParams params;
  double velocity_m_s = 0.0;             // superficial inlet velocity
  double kinematic_viscosity_m2_s = 0.0;
  long cells = 0;                        // written into constant/polyMesh (the dual's with polyhedra; 0 when
                                         // snappyHexMesh makes them)
  BedSection section;                    // where the pressure drop is measured
  double aspect_ratio = 0.0;             // D_h / d, for the correlation
  double inlet_area_m2 = 0.0;
  double d_ref_m = 0.0;
  std::optional<double> fluid_volume_m3;  // of gmsh's cells (the flow result has the solved cells' own)
  // snappyHexMesh's cells: the volume the fluid surface encloses, which they should fill.
  std::optional<double> surface_volume_m3;
  // A known answer (Pa/m), the route's verification: an empty container's fully developed laminar
  // gradient, or a simple cubic column's Stokes drag (analysis/stokes_arrays.hpp). Unset for
  // other beds, which are compared with Eisfeld & Schnitzlein instead.
  std::optional<double> exact_pressure_gradient_pa_m;
  bool particles = false;                // the bed has spheres (a particles patch)
  nlohmann::json to_json() const;        // its report.json entry
};

// Writes the whole case into `case_dir`, built under a temporary name and renamed at the end;
// an existing case is replaced (only with `overwrite`) once the new one is complete:
// constant/polyMesh (from `mesh`, gmsh's cells, or their dual with p.polyhedra; null when
// p.snappy_cells), 0/U, 0/p, transport and turbulence properties, controlDict with pressure and
// flow function objects, fvSchemes, fvSolution, decomposeParDict, Allrun, Allclean, the records
// `bedforge/scene.toml` and `bedforge/bed.csv`, and with p.snappy the snappyHexMesh set-up for the surface `fluid_stl`
// (ASCII STL, a solid per patch, named in `patches`; copied into constant/triSurface).
// `spheres_as_packed`: the mesh's spheres are the bed's own (no contact treatment changed them),
// the condition for comparing a bed with a known answer (a simple cubic column's).
CaseInfo write_case(const std::filesystem::path& case_dir, bool overwrite, const meshing::PolyMesh* mesh,
                    const std::vector<std::string>& patches, const CaseGeometry& g, const Bed& bed,
                    const CaseParams& p, const std::string& note, const std::string& scene_toml,
                    const std::string& bed_csv, const std::filesystem::path& fluid_stl, bool spheres_as_packed);

// The flow solved in a case: the solver's convergence and the bed's pressure gradient.
struct FlowResult {
  double time_s = 0.0;                   // wall time of Allrun
  double solver_peak_memory_mb = 0.0;    // OpenFOAM's largest process
  std::string mesher;                    // what made the cells solved on: "gmsh tetrahedra", "gmsh polyhedral dual", "snappyHexMesh"
  long solved_cells = -1;                // the cells solved on, as Allrun's checkMesh counted them (-1: no checkMesh ran)
  std::optional<double> solved_volume_m3;  // their total volume, as that checkMesh summed it
  // snappyHexMesh's cells: 1 - their volume / the surface's, the fluid they do not fill
  // (throats and gaps narrower than the cells, dropped).
  std::optional<double> volume_lost;
  // Allrun's steps, each with its wall time and its largest process's peak memory (from GNU
  // time when the machine has it: empty otherwise). On N processes that is the largest rank's.
  struct Step {
    std::string name;
    double time_s = 0.0, peak_memory_mb = 0.0;
  };
  std::vector<Step> steps;
  long iterations = 0;
  bool converged = false;                // SIMPLE's own verdict at the residual targets
  double residual_u = 0.0, residual_p = 0.0;  // the last iteration's initial residuals
  double pressure_gradient_bed_pa_m = 0.0;    // over the bed section
  double pressure_gradient_change_last_tenth = 0.0;  // relative change over the last tenth of the iterations
  double pressure_drop_inlet_outlet_pa = 0.0;
  double flow_rate_m3_s = 0.0, flow_rate_relative_error = 0.0;
  // Forces along the flow (N, OpenFOAM's forces function object, pressure and viscous, over the
  // whole domain): the drag on the walls and on the particles, and the push of the fluid through
  // the inlet and outlet. Steady flow conserves momentum, so the drag equals the push but for the
  // momentum flux difference between inlet and outlet (rho u^2 A / 3 from a plug to a parabola),
  // the solver's convergence and the wall gradient the forces object takes (a discretisation
  // error, falling as the mesh refines).
  double drag_walls_n = 0.0, drag_particles_n = 0.0, push_inlet_outlet_n = 0.0;
  double drag_walls_viscous_n = 0.0, drag_particles_viscous_n = 0.0;  // their shear; the rest is pressure (form drag)
  double wall_share_of_drag = 0.0;            // drag_walls / (drag_walls + drag_particles)
  double force_balance_relative_error = 0.0;  // (drag_walls + drag_particles) / push - 1
  // A case with a known answer (no correlation is compared): the exact gradient and the relative
  // error dp/L / exact - 1. Otherwise unset and the correlation's fields below are filled.
  std::optional<double> exact_pa_m;
  double relative_error_to_exact = 0.0;
  // The correlation at the section's meshed void fraction, when known (not on snappyHexMesh's cells).
  std::optional<double> eisfeld_schnitzlein_pa_m, ratio_to_eisfeld_schnitzlein, void_fraction_section;
  // The same at the section's exact void fraction of the spheres as packed: the bed the
  // correlation describes, whatever the contact treatment and the facets did to it.
  double eisfeld_schnitzlein_bed_pa_m = 0.0;
  double ratio_to_eisfeld_schnitzlein_bed = 0.0;
  double void_fraction_section_bed = 0.0;
  // The wall's share of the wetted area at that void fraction: its share of the drag in the
  // correlation's wall term (analysis::wall_wetted_area_share), to hold the measured share against.
  double wall_share_of_drag_eisfeld_schnitzlein = 0.0;
  nlohmann::json history;                // per iteration: residuals and the bed's gradient against time
  nlohmann::json to_json() const;        // the case entry's "flow"
};

// The first of the OpenFOAM programs Allrun needs on `processors` processes (simpleFoam and
// checkMesh; decomposePar, reconstructPar and mpirun on more than one) that is not on PATH;
// empty when all are.
std::string missing_openfoam_program(int processors);

// Runs `case.directory/Allrun` (OpenFOAM on PATH, WM_PROJECT_DIR defaulting to Debian's) and
// reads back the solver's convergence and the pressure drop, compared with Eisfeld &
// Schnitzlein at the section's own void fraction. Shows the solver's iteration on `progress`
// while it runs. ConvergenceError when snappyHexMesh's cells lost the inlet or the outlet (the
// fluid they kept does not reach it), naming the settings that make finer cells;
// std::runtime_error naming the log and Allrun's last words when another step fails.
FlowResult run_case(const CaseInfo& c, Progress& progress);

}  // namespace bedforge::cases
