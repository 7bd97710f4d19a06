#include "core/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace bedforge {

Progress::Progress(std::string stage, bool enabled)
    : stage_(std::move(stage)), enabled_(enabled), start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { finish(); }

bool Progress::wanted_by_default() {
  const char* ci = std::getenv("CI");
  return ::isatty(STDERR_FILENO) && !(ci && *ci && std::string(ci) != "false" && std::string(ci) != "0");
}

void Progress::update(const std::string& status, double fraction) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (shown_ && now - last_ < std::chrono::milliseconds(250)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  std::string eta;
  if (fraction > 0.01 && fraction <= 1.0) eta = fmt::format(", ETA {:.0f} s", elapsed * (1.0 - fraction) / fraction);
  std::fprintf(stderr, "\r\033[K%s: %s (%.0f s%s)", stage_.c_str(), status.c_str(), elapsed, eta.c_str());
  std::fflush(stderr);
  shown_ = true;
}

void Progress::finish() {
  if (enabled_ && shown_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  shown_ = false;
}

}  // namespace bedforge
