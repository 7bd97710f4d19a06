#pragma once
#include <chrono>
#include <string>

namespace bedforge {

// One self-overwriting status line on stderr for long stages, shown only when stderr is a
// terminal and CI is unset, so logs and CI stay quiet. Updates are rate-limited to 4 per second.
class Progress {
 public:
  Progress(std::string stage, bool enabled);
  ~Progress();
  // `fraction` in [0, 1] gives an ETA; pass a negative value when the end is not known.
  void update(const std::string& status, double fraction = -1.0);
  void finish();
  static bool wanted_by_default();

 private:
  std::string stage_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace bedforge
