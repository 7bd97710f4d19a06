#include "core/thread_governor.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

namespace bedforge {

ThreadGovernor::Probe ThreadGovernor::system_probe() {
  return {[] {
            // "0.52 0.58 0.59 3/467 12345": the fourth field is runnable/total scheduling entities.
            std::ifstream in("/proc/loadavg");
            std::string avg1, avg5, avg15, tasks;
            if (!(in >> avg1 >> avg5 >> avg15 >> tasks)) return 0;
            try {
              return std::stoi(tasks.substr(0, tasks.find('/')));
            } catch (const std::exception&) {
              return 0;
            }
          },
          [] { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }};
}

ThreadGovernor::ThreadGovernor()
    : ThreadGovernor(omp_get_max_threads(), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())),
                     system_probe()) {}

ThreadGovernor::ThreadGovernor(int threads, int cores, Probe probe)
    : max_(std::max(1, threads)),
      cores_(std::max(1, cores)),
      restore_(omp_get_max_threads()),
      current_(restore_),
      probe_(std::move(probe)) {
  use(max_);
}

ThreadGovernor::~ThreadGovernor() {
  if (current_ != restore_) omp_set_num_threads(restore_);
}

void ThreadGovernor::use(int threads) {
  if (threads != current_) omp_set_num_threads(threads);
  current_ = threads;
}

void ThreadGovernor::tick() {
  if (max_ == 1) return;
  if (current_ == 1) ++on_one_;
  ++ticks_;
  const double t = probe_.now();
  const double window = t - since_;
  switch (phase_) {
    case Phase::steady:
      if (window < kRecheck) return;
      since_ = t, ticks_ = 0;
      use(max_);
      if (probe_.runnable() <= cores_) return;  // every runnable task has a core: all threads stay
      ++probes_;
      phase_ = Phase::all;
      return;
    case Phase::all:
      if (window < kWindow || ticks_ < kWindowIterations) return;
      per_iteration_all_ = window / static_cast<double>(ticks_);
      since_ = t, ticks_ = 0;
      use(1);
      phase_ = Phase::one;
      return;
    case Phase::one:
      if (window < kWindow || ticks_ < kWindowIterations) return;
      use(window / static_cast<double>(ticks_) < kMargin * per_iteration_all_ ? 1 : max_);
      since_ = t, ticks_ = 0;
      phase_ = Phase::steady;
      return;
  }
}

}  // namespace bedforge
