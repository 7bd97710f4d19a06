#pragma once
#include <Eigen/Core>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cases/case_params.hpp"
#include "cases/drag_regions.hpp"
#include "core/bed.hpp"
#include "meshing/volume/cell_quality.hpp"
#include "meshing/volume/dual_mesh.hpp"
#include "meshing/volume/poly_mesh.hpp"

namespace bedforge::cases {

// Boundary edges sharper than this (deg; the inlet's and outlet's rims) stay edges of the dual.
inline constexpr double kDualFeatureAngleDeg = 80.0;

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
  // A section periodic along z: its inlet and outlet are one period apart and become cyclic
  // patches, and the bed section is the whole period between them.
  bool periodic = false;
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

// A bound on a treated bed's answer: the untreated bed's known answer (Pa/m). Stokes drag at a
// set flow rate only grows with the solid (Helmholtz's minimum dissipation), so it bounds a bed
// whose treatment added solid from below and one whose treatment took solid from above.
struct KnownBound {
  double pa_m = 0.0;
  bool from_below = true;
  const char* side() const { return from_below ? "below" : "above"; }
  // Whether `pa_m_solved` lies on the bound's side of it.
  bool holds(double pa_m_solved) const { return from_below ? pa_m_solved >= pa_m : pa_m_solved <= pa_m; }
  // Whether an uncertainty band [low, high] (Pa/m) reaches the bound's side, where the
  // mesh-independent value lies.
  bool reached_by(double low, double high) const { return holds(from_below ? high : low); }
  // {"pa_m", "side"} as report.json and study.json hold it; from_json reads it back and throws
  // std::runtime_error when "side" is neither "below" nor "above".
  nlohmann::json to_json() const { return {{"pa_m", pa_m}, {"side", side()}}; }
  static KnownBound from_json(const nlohmann::json& j);
};

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
  // Such a column or array whose contacts were treated: its untreated answer, as a bound.
  std::optional<KnownBound> bound{};
  bool particles = false;                // the bed has spheres (a particles patch)
  bool walls = true;                     // the container has walls (a box periodic on every side has none)
  // A random array of equal spheres in a box periodic on every side at Re_p <= 0.01: van der Hoef
  // et al.'s Stokes drag (analysis::van_der_hoef_gradient) at the spheres' solid fraction and
  // diameter (m) as solved, and its gradient (Pa/m). Compared beside Eisfeld & Schnitzlein.
  struct StokesArray {
    double solid_fraction = 0.0, diameter_m = 0.0, pa_m = 0.0;
  };
  std::optional<StokesArray> stokes_array{};
  // Such an array left without it, and why (their fit is for equal spheres); "" otherwise.
  std::string stokes_array_not_compared{};
  // A periodic section: cyclic inlet and outlet, the flow driven by meanVelocityForce at this
  // volume-mean velocity (m/s; the superficial one over the cells' void fraction).
  std::optional<double> mean_velocity_m_s = std::nullopt;
  // On polyhedra written here: their worst figures, as checked (check_polyhedra).
  std::optional<meshing::JudgedQuality> polyhedra_quality = std::nullopt;
  // With case.drag_by_gap_d: the particles' patches by gap, their faces and areas (no forces yet),
  // and the walls' faces beyond the section's planes (split_walls_at_section).
  std::vector<GapBand> gap_bands{};
  long wall_faces_beyond_section = 0;
  nlohmann::json to_json() const;        // its report.json entry
};

// The known answers and references a case is compared with, set in `info` from `bed` and what
// info already holds (params, velocity_m_s, section, particles, walls): exact_pressure_gradient_pa_m
// for an empty container (Hagen-Poiseuille or the duct's series) or a simple cubic column or
// array at Re_p <= 0.01 (Zick & Homsy) whose spheres are the bed's own; `bound` for such a
// column or array whose treatment only added or only took solid; else, for a box periodic on
// every side at Re_p <= 0.01, stokes_array (equal spheres: van der Hoef et al. at the solid
// fraction and diameter solved) or stokes_array_not_compared (why not). Called by write_case.
void set_known_answers(CaseInfo& info, const Bed& bed, const TreatedSolid& treated);

// Writes the whole case into `case_dir`, built under a temporary name and renamed at the end;
// an existing case is replaced (only with `overwrite`) once the new one is complete:
// constant/polyMesh (from `mesh`, gmsh's cells, or their dual with p.polyhedra; null when
// p.snappy_cells; a periodic section's inlet and outlet made cyclic, cyclic_patches.hpp), 0/U, 0/p,
// system/fvOptions for a periodic section, transport and turbulence properties, controlDict with pressure and
// flow function objects, fvSchemes, fvSolution, decomposeParDict, Allrun, Allclean, the records
// `bedforge/scene.toml` and `bedforge/bed.csv`, and with p.snappy the snappyHexMesh set-up for the surface `fluid_stl`
// (ASCII STL, a solid per patch, named in `patches`; copied into constant/triSurface).
// `treated`: what the contact treatment did to the spheres, which decides the known answers the
// case is compared with (set_known_answers).
CaseInfo write_case(const std::filesystem::path& case_dir, bool overwrite, const meshing::PolyMesh* mesh,
                    const std::vector<std::string>& patches, const CaseGeometry& g, const Bed& bed,
                    const CaseParams& p, const std::string& note, const std::string& scene_toml,
                    const std::string& bed_csv, const std::filesystem::path& fluid_stl, const TreatedSolid& treated);

// The pieces an earlier run of a case left (processor*/ and piece_layers/) moved out of
// case_dir while the case is written anew (returns where to), and put back after it, those of
// the first `pieces` (pipeline/piece_stage.hpp keeps what was made from the same inputs).
std::filesystem::path set_pieces_aside(const std::filesystem::path& case_dir);
void put_pieces_back(const std::filesystem::path& aside, const std::filesystem::path& case_dir, int pieces);

// One piece of a decomposed case (meshing/volume/processor_patches.hpp), as decomposePar would
// have written it: `mesh` into case_dir/processor<piece>/constant/polyMesh, the case's 0/ fields
// copied beside it (their boundaries take the processor patches from setConstraintTypes), and
// `report` as processor<piece>/bedforge_piece.json, and its processor patches' faces as
// processor<piece>/kProcessorFacesFile (meshing::write_processor_faces), which the run compares
// with its neighbours' before OpenFOAM reads them. Built under a temporary name and renamed,
// replacing an earlier piece only once complete. The case (case_dir/0) is written first.
inline constexpr const char* kProcessorFacesFile = "bedforge_processor_faces.bin";
void write_case_piece(const std::filesystem::path& case_dir, int piece, const meshing::PolyMesh& mesh, bool binary,
                      const std::string& note, const nlohmann::json& report);
void write_case_piece(const std::filesystem::path& case_dir, int piece, const meshing::PolyhedralMesh& mesh,
                      bool binary, const std::string& note, const nlohmann::json& report);

}  // namespace bedforge::cases
