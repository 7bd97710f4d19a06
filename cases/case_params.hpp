#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/scene_section.hpp"

namespace bedforge::cases {

// SIMPLE's targets for the initial residuals of U and p when [case] residual_u and residual_p are unset.
inline constexpr double kResidualU = 1.0e-4;
inline constexpr double kResidualP = 1.0e-4;
inline constexpr double kResidualULayered = 1.0e-2;  // U's on cells with prism layers
// Both on a periodic section without prism layers: there the driving gradient that
// meanVelocityForce sets falls towards its value slowly, and at 1e-4 SIMPLE stopped 0.34 % above
// it on a Stokes array of 65 k polyhedra, at 1e-6 0.002 % (docs/defaults.md).
inline constexpr double kResidualPeriodic = 1.0e-6;
// A solve runs on past its residual targets until dp/L is settled to case.iteration_tolerance
// (analysis::settled_within on its own history), by at most as many iterations again as it took
// to reach them: at 1e-4 a Stokes column's finest mesh stopped 0.55 % short of its settled dp/L,
// the README's bed at Re_p = 1 0.004 % (docs/findings.md, 2026-12-07).
inline constexpr double kIterationTolerance = 1.0e-3;
// SIMPLE's own residualControl is written at this fraction of the targets, so that it does not
// stop the solve before bedforge finds dp/L settled; a case run by hand solves to it.
inline constexpr double kResidualControlShare = 1.0e-2;
// Bands of case.drag_by_gap_d at most (one forces object each).
inline constexpr std::size_t kMostGapBands = 8;
// The meshes of a convergence study when the case is run and the scene names none.
inline constexpr int kStudyLevels = 3;
// What the contact treatment did to the bed's spheres, as a case compares it with known answers
// (meshing::SurfaceParams::sphere_scale and solid_change).
struct TreatedSolid {
  // The one scale every sphere took: 1 the bed's own, the condition for comparing a bed with a
  // known answer; the shrink factor when every sphere was shrunk; 0 not one scale.
  double sphere_scale = 1.0;
  // +1 solid only added (bridges, enlarged spheres), -1 only taken (shrink, caps), 0 kept, both
  // or not known.
  int change = 0;
};

// The OpenFOAM case, scene section [case]: steady laminar incompressible flow (simpleFoam) up
// through the bed, inlet at the bottom.
struct CaseParams {
  double reynolds = 1.0;                // particle Reynolds number rho u d / mu, u superficial, d the reference diameter
  double density_kg_m3 = 1000.0;        // fluid density (water)
  double viscosity_pa_s = 1.0e-3;       // dynamic viscosity (water)
  int iterations = 3000;                // simpleFoam iteration cap (endTime)
  // SIMPLE stops when the initial residuals fall below these. Unset: kResidualP and kResidualU;
  // on a periodic section kResidualPeriodic for both; on cells with prism layers
  // kResidualULayered for U, where U's residual stalls near 3e-3 while the pressure drop has
  // settled (docs/findings.md, 2026-11-26, night). write_case sets them.
  std::optional<double> residual_p, residual_u;
  double iteration_tolerance = kIterationTolerance;  // dp/L's estimated iteration error to settle to (fraction)
  int processors = 1;                   // subdomains in decomposeParDict; Allrun -np N overrides
  // hierarchical: slabs along the column (n = 1 1 N), few interface faces in a column; scotch:
  // graph partitioning, for OpenFOAM builds that have it (Debian's v1912 ships only a stub).
  std::string decomposition = "hierarchical";
  bool binary = true;                   // polyMesh and fields in binary, else ASCII
  // cells = "polyhedra": the case holds the dual polyhedra of gmsh's tetrahedra (as OpenFOAM's
  // polyDualMesh makes them, meshing/volume/dual_mesh.hpp), on which an empty tube's pressure drop
  // comes within 0.25 % of the exact one from some 20 k cells on, not converging to it;
  // "tetrahedra" solves on gmsh's cells, where it reads up to 0.6 % high (docs/defaults.md).
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
  // The particles' drag split by the gap at each face (cases/drag_regions.hpp): the bands' edges,
  // ascending, in reference diameters; empty: one particles patch.
  std::vector<double> drag_by_gap_d;
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

}  // namespace bedforge::cases
