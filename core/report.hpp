#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace bedforge {

// The run's JSON report, DIR/report.json: what made the run (version, scene, seed) and one
// entry per stage with its error measures, the thresholds they were held to, its time and a
// one-line summary. Each stage adds itself to the report already in DIR, like an OpenFOAM
// utility adds to a case.
class Report {
 public:
  static Report load_or_new(const std::filesystem::path& dir);
  void set_provenance(const std::string& version, const nlohmann::json& scene, unsigned long long seed);
  // `stage` must hold "summary" (one line) and "time_s".
  void set_stage(const std::string& name, nlohmann::json stage);
  const nlohmann::json& data() const { return data_; }
  // Writes DIR/report.json and DIR/summary.txt (the version, the seed, each stage's line and the
  // lines of the case's answer, stages.case.answer.lines, when it has one).
  void save(const std::filesystem::path& dir) const;

 private:
  nlohmann::json data_ = nlohmann::json::object();
};

// A stage's cache key: a 64-bit FNV-1a hash, as 16 hex digits, of `inputs` written as compact
// JSON (objects keep their keys sorted, so equal inputs give equal text). A stage passes its own
// scene sections, the program version and its upstream stage's key, so a change anywhere
// upstream changes it.
std::string stage_key(const nlohmann::json& inputs);

// A convergence history (an array of points, each a stage's error measures against elapsed
// time) thinned to at most `max_points` evenly spaced points, the last one kept, so a report
// stays small however long the run.
nlohmann::json thin_history(const nlohmann::json& history, std::size_t max_points = 300);

}  // namespace bedforge
