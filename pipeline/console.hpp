#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "core/progress.hpp"
#include "core/stage_meter.hpp"

namespace bedforge::pipeline {

// Where the stages speak to a person: one summary line per stage on stdout (none when quiet),
// and progress lines where Progress allows them (a terminal, CI unset).
struct Console {
  bool progress = Progress::wanted_by_default();
  bool quiet = false;
  void line(const std::string& s) const;
};

// Ends a stage: its time and peak memory into `report`, and `line` with both appended as its
// "summary", which is printed.
void finish_stage(nlohmann::json& report, const StageMeter& meter, const std::string& line, const Console& console);

}  // namespace bedforge::pipeline
