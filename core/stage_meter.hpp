#pragma once
#include <chrono>
#include <nlohmann/json.hpp>

namespace bedforge {

// Run time and peak memory of one stage. Starting a meter resets the kernel's high-water mark
// of the process's resident memory (Linux: /proc/self/clear_refs), so the peak a stage reports
// is its own and not that of an earlier, larger stage. Where the reset is refused the process
// peak so far is reported, and `peak_memory_scope` says so.
class StageMeter {
 public:
  StageMeter();
  double seconds() const;
  // Peak resident memory since the meter started, MB (2^20 bytes).
  double peak_memory_mb() const;
  // Writes time_s, peak_memory_mb and peak_memory_scope ("stage" or "process") into `stage`.
  void record(nlohmann::json& stage) const;

 private:
  std::chrono::steady_clock::time_point start_;
  bool reset_ = false;
};

// Largest peak resident memory of the child processes waited for so far (OpenFOAM's solvers), MB.
double children_peak_memory_mb();

// Memory this process may still take, bytes: the kernel's MemAvailable, or what the cgroup's
// limit leaves if that is less; for one of the ranks Open MPI started on this machine
// (OMPI_COMM_WORLD_LOCAL_SIZE), at most its share of that as it was at the first call, less
// what the rank has taken since. Infinity when neither can be read.
double available_memory_bytes();

// This process's resident memory now, and its peak (since the last StageMeter started, where
// the kernel allows the reset), bytes; NaN where /proc/self/status cannot be read.
double resident_memory_bytes();
double peak_resident_memory_bytes();

// Hands memory the allocator keeps after a free back to the system: tcmalloc (when the program
// links it) and glibc hold freed pages for reuse, and a stage that frees one large structure
// before building the next would otherwise carry both in its resident peak.
void release_free_memory();

}  // namespace bedforge
