#include "core/stage_meter.hpp"

#include <sys/resource.h>

#include <fstream>
#include <string>

namespace bedforge {

namespace {

// VmHWM of /proc/self/status in MB, or the process's rusage peak where /proc is missing.
double high_water_mark_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

}  // namespace

StageMeter::StageMeter() : start_(std::chrono::steady_clock::now()) {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";  // 5: reset the peak resident set size to the current one
  clear.flush();
  reset_ = static_cast<bool>(clear);
}

double StageMeter::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double StageMeter::peak_memory_mb() const { return high_water_mark_mb(); }

void StageMeter::record(nlohmann::json& stage) const {
  stage["time_s"] = seconds();
  stage["peak_memory_mb"] = peak_memory_mb();
  stage["peak_memory_scope"] = reset_ ? "stage" : "process";
}

double children_peak_memory_mb() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

}  // namespace bedforge
