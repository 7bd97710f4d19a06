#pragma once
#include <functional>

namespace bedforge {

// Chooses, while an iterative loop runs, between all of its OpenMP threads and one. When other
// processes want the cores, every join of a parallel loop waits for whichever thread the system
// has descheduled, and one thread finishes first (docs/defaults.md, "Threads"); on a quiet
// machine all threads do. So: when more tasks are runnable than there are cores, time a window
// of iterations on all threads and one on a single thread, keep the faster, and look again a
// second later. A quiet machine is never probed. The calling thread's OpenMP thread count is
// restored on destruction. Results must not depend on the thread count (the packer's do not).
class ThreadGovernor {
 public:
  // What the governor reads: tasks runnable on the whole machine now (ours included), and a
  // clock in seconds. Replaced in tests.
  struct Probe {
    std::function<int()> runnable;
    std::function<double()> now;
  };
  static Probe system_probe();  // /proc/loadavg's runnable count (0 where it cannot be read), steady_clock

  // `threads`: the most to use (OMP_NUM_THREADS, or the cores, by default); `cores`: the cores.
  ThreadGovernor();
  ThreadGovernor(int threads, int cores, Probe probe);
  ~ThreadGovernor();
  ThreadGovernor(const ThreadGovernor&) = delete;
  ThreadGovernor& operator=(const ThreadGovernor&) = delete;

  // Called once an iteration, outside parallel regions, on the thread that starts them.
  void tick();

  int most() const { return max_; }
  int threads() const { return current_; }
  int probes() const { return probes_; }
  long iterations_on_one_thread() const { return on_one_; }

  static constexpr double kRecheck = 1.0;  // s between looks at the machine's load
  static constexpr double kWindow = 0.2;   // s (and at least kWindowIterations) timed at each count
  static constexpr long kWindowIterations = 5;
  static constexpr double kMargin = 0.8;   // one thread is kept only when this much faster per iteration

 private:
  enum class Phase { steady, all, one };
  void use(int threads);

  int max_, cores_, restore_, current_;
  Probe probe_;
  Phase phase_ = Phase::steady;
  double since_ = -1e300;  // start of the current window (steady: of the last look)
  long ticks_ = 0;         // iterations in the current window
  double per_iteration_all_ = 0.0;
  int probes_ = 0;
  long on_one_ = 0;
};

}  // namespace bedforge
