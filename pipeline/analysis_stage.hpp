#pragma once
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/bed_analysis.hpp"
#include "core/bed.hpp"
#include "pipeline/console.hpp"

namespace bedforge::pipeline {

// The analysis of a bed: its files and its report entry.
struct AnalysisStage {
  std::map<std::string, std::string> csv_files;  // file name -> contents (profiles, contacts)
  nlohmann::json report;                         // stages.analysis, with "files" (the names above) and "summary"
};

// Void fractions, profiles, contacts and force balance of `bed` (m), by analysis::analyse_bed.
AnalysisStage analysis_stage(const Bed& bed, const analysis::AnalysisParams& params, const Console& console);

}  // namespace bedforge::pipeline
