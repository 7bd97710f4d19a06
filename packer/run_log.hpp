#pragma once
#include <fmt/format.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.hpp"
#include "core/progress.hpp"
#include "core/report.hpp"
#include "core/thread_governor.hpp"

namespace bedforge::packer {

// Book-keeping shared by the packing modes: the iteration budget, per-stage iterations and
// time, the convergence history (error measure against elapsed time) and recovery events; and
// the thread count, which it lowers to one while other processes make that faster.
class RunLog {
 public:
  RunLog(long max_iterations, Progress& progress)
      : max_iterations_(max_iterations), progress_(progress), start_(std::chrono::steady_clock::now()),
        stage_start_(start_) {}

  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  long iterations() const { return iterations_; }

  // Counts one iteration; ConvergenceError once the budget is spent. `where_and_state()` says
  // where the run was; it is called only then, so the hot loop formats nothing.
  template <class Describe>
  void tick(Describe where_and_state) {
    governor_.tick();
    if (++iterations_ > max_iterations_)
      throw ConvergenceError(fmt::format("the packer reached packing.soft_sphere.max_iterations = {} in {}; raise "
                                         "it if the bed was still progressing (see the history in the report)",
                                         max_iterations_, where_and_state()));
  }

  void begin_stage(const std::string& name) {
    end_stage();
    stage_ = name;
    stage_start_ = std::chrono::steady_clock::now();
    stage_iterations_start_ = iterations_;
  }
  void end_stage() {
    if (stage_.empty()) return;
    auto& s = stages_[stage_];
    if (s.is_null()) s = {{"iterations", 0L}, {"time_s", 0.0}};
    s["iterations"] = s.value("iterations", 0L) + (iterations_ - stage_iterations_start_);
    s["time_s"] = s.value("time_s", 0.0) +
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - stage_start_).count();
    stage_.clear();
  }
  const std::string& stage() const { return stage_; }

  // One point of the convergence history; `fields` holds the stage's error measures.
  void record(nlohmann::json fields) {
    fields["iteration"] = iterations_;
    fields["time_s"] = elapsed();
    fields["stage"] = stage_;
    history_.push_back(std::move(fields));
  }
  void recovery(nlohmann::json event) {
    event["iteration"] = iterations_;
    event["stage"] = stage_;
    recoveries_.push_back(std::move(event));
  }
  std::size_t recoveries() const { return recoveries_.size(); }
  void show(const std::string& status, double fraction = -1.0) { progress_.update(status, fraction); }

  nlohmann::json to_json(std::size_t max_points = 300) {
    end_stage();
    return {{"iterations", iterations_},
            {"stages", stages_},
            {"recoveries", recoveries_},
            {"threads",
             {{"most", governor_.most()},
              {"load_probes", governor_.probes()},
              {"iterations_on_one_thread", governor_.iterations_on_one_thread()}}},
            {"history", thin_history(history_, max_points)}};
  }

 private:
  long max_iterations_;
  Progress& progress_;
  long iterations_ = 0, stage_iterations_start_ = 0;
  std::chrono::steady_clock::time_point start_, stage_start_;
  std::string stage_;
  nlohmann::json stages_ = nlohmann::json::object();
  nlohmann::json history_ = nlohmann::json::array();
  nlohmann::json recoveries_ = nlohmann::json::array();
  ThreadGovernor governor_;
};

}  // namespace bedforge::packer
