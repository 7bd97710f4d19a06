#include "pipeline/analysis_stage.hpp"

namespace bedforge::pipeline {

AnalysisStage analysis_stage(const Bed& bed, const analysis::AnalysisParams& params, const Console& console) {
  const StageMeter meter;
  analysis::AnalysisResult a = analysis::analyse_bed(bed, params);
  AnalysisStage out{std::move(a.csv_files), std::move(a.report)};
  // The names let a later run see whether the files are still there to reuse.
  for (const auto& [name, csv] : out.csv_files) out.report["files"].push_back(name);
  finish_stage(out.report, meter, a.summary, console);
  return out;
}

}  // namespace bedforge::pipeline
