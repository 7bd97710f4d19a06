#include "core/stage_meter.hpp"

#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

// tcmalloc's C entry point, null unless the program links tcmalloc.
extern "C" void MallocExtension_ReleaseFreeMemory() __attribute__((weak));

namespace bedforge {

namespace {

// A line of /proc/self/status ("VmHWM:", "VmRSS:") in kB; NaN where it cannot be read.
double status_kb(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(key.size()));
  return std::numeric_limits<double>::quiet_NaN();
}

// VmHWM in MB, or the process's rusage peak where /proc is missing.
double high_water_mark_mb() {
  const double kb = status_kb("VmHWM:");
  if (!std::isnan(kb)) return kb / 1024.0;
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

double available_memory_bytes() {
  double available = std::numeric_limits<double>::infinity();
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kb = 0.0;
    meminfo >> kb;
    if (key == "MemAvailable:") available = kb * 1024.0;
    meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  std::ifstream max("/sys/fs/cgroup/memory.max"), current("/sys/fs/cgroup/memory.current");
  std::string limit;
  double used = 0.0;
  if (max >> limit && limit != "max" && current >> used) available = std::min(available, std::stod(limit) - used);
  // Ranks of one mpirun on this machine share it: each may take its share of what was available
  // when it first asked (the others, started with it, had taken little then).
  const char* ranks = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const int local = ranks ? std::max(1, std::atoi(ranks)) : 1;
  if (local == 1) return available;
  static const double share = available / local, resident_then = resident_memory_bytes();
  const double taken = std::isnan(resident_then) ? 0.0 : std::max(0.0, resident_memory_bytes() - resident_then);
  return std::min(available, share - taken);
}

double resident_memory_bytes() { return status_kb("VmRSS:") * 1024.0; }

double peak_resident_memory_bytes() { return status_kb("VmHWM:") * 1024.0; }

void release_free_memory() {
  if (MallocExtension_ReleaseFreeMemory)
    MallocExtension_ReleaseFreeMemory();
  else
    malloc_trim(0);
}

}  // namespace bedforge
