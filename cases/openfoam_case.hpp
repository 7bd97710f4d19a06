#pragma once
#include <Eigen/Core>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/progress.hpp"
#include "core/scene_section.hpp"
#include "meshing/poly_mesh.hpp"

namespace bedforge::cases {

// The OpenFOAM case, scene section [case]: steady laminar incompressible flow (simpleFoam) up
// through the bed, inlet at the bottom.
struct CaseParams {
  double reynolds = 1.0;                // particle Reynolds number rho u d / mu, u superficial, d the reference diameter
  double density_kg_m3 = 1000.0;        // fluid density (water)
  double viscosity_pa_s = 1.0e-3;       // dynamic viscosity (water)
  int iterations = 3000;                // simpleFoam iteration cap (endTime)
  double residual_p = 1.0e-4;           // SIMPLE stops when the initial residuals fall below these (on
                                        // these tetrahedral meshes p plateaus near 5e-5 once dp has 4 digits)
  double residual_u = 1.0e-4;
  int processors = 1;                   // subdomains in decomposeParDict; Allrun -np N overrides
  // hierarchical: slabs along the column (n = 1 1 N), few interface faces in a column; scotch:
  // graph partitioning, for OpenFOAM builds that have it (Debian's v1912 ships only a stub).
  std::string decomposition = "hierarchical";
  bool binary = true;                   // polyMesh and fields in binary, else ASCII
  bool snappy = false;                  // also write the snappyHexMesh set-up (Allrun -snappy)
  double snappy_cell_d = 0.25;          // snappyHexMesh background cell, in reference diameters
  int snappy_level = 2;                 // refinement levels at particles and walls
  double section_exclude_d = 0.5;       // bed section for the pressure drop: floor (or clip inlet) + this to bed top (or clip outlet) - this
  bool run = false;                     // run Allrun after writing and read the pressure drop back
  bool run_snappy = false;              // run_mesh = "snappy": the run meshes with snappyHexMesh first (needs snappy)
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
  double inlet_z = 0.0, outlet_z = 0.0, bed_top = 0.0;
};

// Bed section over which the pressure drop is measured: its planes and its void fraction as
// meshed (cells with their centre between the planes over the container's volume between them),
// from the mesh's cell geometry.
struct BedSection {
  double z_low = 0.0, z_high = 0.0, void_fraction = 0.0;
};
BedSection bed_section(const meshing::CellGeometry& cells, const CaseGeometry& g, double exclude_d);

// InputError when `case_dir` exists and `overwrite` is false (checked again by write_case;
// callers check first to refuse before the long stages).
void refuse_existing_case(const std::filesystem::path& case_dir, bool overwrite);

// Writes the whole case into `case_dir`, built under a temporary name and renamed at the end;
// an existing case is replaced (only with `overwrite`) once the new one is complete: constant/polyMesh, 0/U, 0/p, transport and turbulence
// properties, controlDict with pressure and flow function objects, fvSchemes, fvSolution,
// decomposeParDict, Allrun, Allclean, and the records `bedforge/scene.toml` and
// `bedforge/bed.csv`. Returns the case's report entry.
nlohmann::json write_case(const std::filesystem::path& case_dir, bool overwrite, const meshing::PolyMesh& mesh,
                          const CaseGeometry& g, const CaseParams& p, const std::string& note,
                          const std::string& scene_toml, const std::string& bed_csv, const std::string& fluid_stl);

// Runs `case_dir/Allrun` (OpenFOAM on PATH, WM_PROJECT_DIR defaulting to Debian's) and reads
// back the solver's convergence and the pressure drop, compared with Eisfeld & Schnitzlein at
// the section's own void fraction. Shows the solver's iteration on `progress` while it runs.
// std::runtime_error naming the log when the solver fails.
nlohmann::json run_case(const std::filesystem::path& case_dir, const nlohmann::json& case_report, Progress& progress);

}  // namespace bedforge::cases
