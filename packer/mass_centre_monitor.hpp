#pragma once
#include <algorithm>
#include <cmath>
#include <deque>

namespace bedforge::packer {

// The stopping test of Salvat et al. (2005), Sec. 3.3: the bed's mass centre, sampled at a
// fixed interval, has settled when `samples` successive values lie within `tolerance` (relative).
class MassCentreMonitor {
 public:
  MassCentreMonitor(int samples, double tolerance) : samples_(samples), tolerance_(tolerance) {}
  void clear() { values_.clear(); }
  void add(double mass_centre) {
    values_.push_back(mass_centre);
    if (static_cast<int>(values_.size()) > samples_) values_.pop_front();
  }
  bool settled() const {
    if (static_cast<int>(values_.size()) < samples_) return false;
    const auto [lo, hi] = std::minmax_element(values_.begin(), values_.end());
    double mean = 0.0;
    for (double v : values_) mean += v;
    mean /= static_cast<double>(values_.size());
    return *hi - *lo <= tolerance_ * std::abs(mean);
  }

 private:
  int samples_;
  double tolerance_;
  std::deque<double> values_;
};

}  // namespace bedforge::packer
