#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/convergence_study.hpp"

namespace bedforge::pipeline {

// What a run with a solved case answers: the bed's pressure gradient dp/L over the bed section
// (Pa/m), its best estimate and uncertainty band from the mesh-convergence study, and the
// reference it is compared with, each number with where it comes from.
//   best estimate: the Richardson extrapolation of the finest three levels (Celik et al. 2008),
//                  given only when they converge monotonically at an apparent order within
//                  analysis::kAsymptoticOrder;
//   band:          the finest level's value +- its grid convergence index (Roache 1994; safety
//                  factor 1.25 for three meshes, meant to hold the mesh-independent value with
//                  about 95 % confidence; Celik et al. 2008). It holds the best estimate, which
//                  lies 1 / 1.25 of the half-width from the finest value;
//   reference:     Eisfeld & Schnitzlein (2001) at the section's void fraction of the spheres as
//                  packed, +- its stated accuracy (docs/reference.md), or a known answer (an
//                  empty tube's, a simple cubic array's), exact, or a treated array's bound.
//   iteration error: what each level's dp/L would still have moved had its solve run on
//                  (analysis::iteration_error), said beside the band it is not part of.
struct PressureDropAnswer {
  double section_low_m = 0.0, section_high_m = 0.0;  // the section's planes
  bool periodic = false;                              // the section is one period of a periodic bed
  double reynolds = 0.0;
  double finest_pa_m = 0.0;                          // level 1, the scene's own mesh
  long finest_cells = 0;
  bool finest_converged = false;                     // simpleFoam reached its residual targets
  std::vector<analysis::GridLevel> levels;           // every level that gave a value: cell size (m), dp/L
  double d_ref_m = 0.0;
  // Set together, when the study allows them.
  std::optional<double> best_pa_m, band_low_pa_m, band_high_pa_m;
  double gci_fine = 0.0, order = 0.0;                // with best_pa_m
  // The reference.
  std::string reference_name;                        // "Eisfeld & Schnitzlein (2001)" or the known answer's
  double reference_pa_m = 0.0;
  std::optional<double> reference_accuracy;          // relative, e.g. 0.2; none for an exact answer
  std::optional<double> void_fraction_bed;           // where the correlation was taken
  // A treated simple cubic column or array: the reference is its untreated answer, this bound.
  std::optional<cases::KnownBound> reference_bound;
  // A random array in a box periodic on every side (cases::CaseInfo::stokes_array): van der Hoef et
  // al.'s Stokes drag (Pa/m) at the solid fraction of the spheres as solved, said beside the reference.
  std::optional<double> stokes_array_pa_m, stokes_array_solid_fraction;
  std::string stokes_array_not_compared;  // such an array left without it: why (cases::CaseInfo's)
  // Without a best estimate: why not, and what to change, with its cost by this run's own levels.
  std::string why_no_estimate;
  // The levels given a value whose polyhedra fail checkMesh's limits: (level, cells failing).
  std::vector<std::pair<int, long>> failing_check_mesh;
  // Each level that gave a value and has an estimate (reports before 2026-12-07 have none): the
  // level and its iteration error; and the residual targets its solves stopped at.
  std::vector<std::pair<int, analysis::IterationError>> iteration_errors;
  // With a best estimate whose three levels were each looked at: the study of their values with
  // the iteration errors estimated taken out (a level whose changes did not shrink as solved).
  std::optional<analysis::GridConvergence> without_iteration_error;
  double residual_u = 0.0, residual_p = 0.0;
  std::string advice;
  // The lines printed at the end of a run and kept in summary.txt.
  std::vector<std::string> lines() const;
  // The iteration errors' line, and advice when they are not small against the band.
  std::vector<std::string> iteration_lines() const;
  nlohmann::json to_json() const;
};

// The particle Reynolds number past which a packed bed's flow is no longer steady: Dybbs & Edwards
// (1984) saw unsteady laminar flow from a pore Reynolds number of about 150 (on the pores' mean
// size and velocity; docs/reference.md), which at a void fraction of 0.4 is about Re_p (pore
// velocity u / eps, pore size (2/3) eps / (1 - eps) d: 1.1 Re_p). Past it simpleFoam's steady
// solution is not the flow the bed has, and the answer says so.
inline constexpr double kUnsteadyFlowReynolds = 150.0;

// The levels' iteration errors are called out, with the residual targets to lower, when taking
// them out of the three levels the band rests on moves the best estimate by more than this share
// of the band's half-width (the GCI), or when one of those levels' dp/L did not settle (its
// changes did not shrink) and moved by more than that share over its last block of iterations
// (analysis::iteration_error's).
// bedforge's choice, not a published rule: a tenth keeps what the iterations leave below a tenth
// of what the meshes do.
inline constexpr double kIterationErrorShareOfBand = 0.1;

// What a finer study would cost, from this study's levels: a study whose every mesh length is
// 1 / ratio of this one's (level_lengths(scene, 1 / ratio)).
struct FinerStudyCost {
  double scale = 1.0;          // of the scene's mesh lengths
  double cells = 0.0;          // its finest level's: this finest's x ratio^3 (cells fill the volume)
  double finest_time_s = 0.0;  // its finest level's surface, mesh and flow, by a power law in the
                               // cells fitted to this study's levels' own times
  double study_time_s = 0.0;   // its whole study: that, and this study's levels but the coarsest
  double peak_memory_mb = 0.0; // this finest's solver peak x the cells' ratio
};
FinerStudyCost finer_study_cost(const ConvergenceStudy& study, double ratio, double solver_peak_memory_mb);

// The case's record (stages.case as run_scene writes it, built now or reused) and its study, if
// any, made into the answer. `scene` gives the lengths a finer study would set. An unsolved
// case (no "flow") has no answer: std::nullopt.
std::optional<PressureDropAnswer> pressure_drop_answer(const Scene& scene, const nlohmann::json& case_entry,
                                                       const ConvergenceStudy* study);

// The answer as a picture: dp/L against the cell size h / d, the levels, the power law of the
// finest three through the best estimate at h = 0, the band and the reference with its accuracy.
// An SVG document.
std::string answer_svg(const PressureDropAnswer& answer);

}  // namespace bedforge::pipeline
