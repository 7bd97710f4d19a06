#include "pipeline/console.hpp"

#include <fmt/format.h>

#include <cstdio>

namespace bedforge::pipeline {

void Console::line(const std::string& s) const {
  if (quiet) return;
  std::printf("%s\n", s.c_str());
  std::fflush(stdout);  // a log piped to a file shows each finished stage, even of a run killed later
}

void finish_stage(nlohmann::json& report, const StageMeter& meter, const std::string& line, const Console& console) {
  meter.record(report);
  report["summary"] = fmt::format("{}, {:.2f} s, {:.0f} MB", line, report["time_s"].get<double>(),
                                  report["peak_memory_mb"].get<double>());
  console.line(report["summary"].get<std::string>());
}

}  // namespace bedforge::pipeline
