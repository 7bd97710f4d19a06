#pragma once
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "core/bed.hpp"
#include "core/scene_section.hpp"

namespace bedforge::analysis {

// Scene section [analysis]. Lengths in reference diameters d (the bed's Sauter mean diameter);
// the contact tolerance in smallest diameters, like the packer's tolerances.
struct AnalysisParams {
  double exclude_d = 2.0;              // slab excluded at the floor and below the top for "central" values
  double radial_bin_d = 0.05;          // radial profile and centre distribution bin width
  double axial_bin_d = 0.05;           // axial profile bin height
  double contact_tolerance_d = 1e-4;   // largest surface gap still counted as a contact
  bool line_intersection = false;      // also radial profiles by line intersection (Reyes & Iglesia)
  double line_step_d = 0.02;           // height step of the line-intersection z-average
};
AnalysisParams read_analysis_params(SceneSection& section);
nlohmann::json to_json(const AnalysisParams& p);

// Void fraction of the whole bed (floor to the top of the highest sphere) and of the central
// slab, with the slab's bounds; the slab is null when the bed is shorter than 2 exclude_d. A
// periodic section (container.axial_period() = H) has no ends: both are over one period, [0, H].
nlohmann::json void_fraction_summary(const Bed& bed, const AnalysisParams& p);

struct AnalysisResult {
  nlohmann::json report;                        // for report.json
  std::map<std::string, std::string> csv_files; // file name -> contents
  std::string summary;                          // one line
};

// Everything the analysis measures: void fractions, radial (central slab) and axial profiles,
// radial centre distribution, coordination numbers (all spheres; bulk spheres more than
// exclude_d from walls, floor and top, rattlers with fewer than 4 contacts set apart), wall and
// floor contacts, maximum overlaps and the force residual. A periodic section: profiles over
// the whole period with every sphere's images, contacts through the period, no floor and no
// force residual (packed without gravity).
AnalysisResult analyse_bed(const Bed& bed, const AnalysisParams& p);

}  // namespace bedforge::analysis
