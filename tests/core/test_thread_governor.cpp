#include "core/thread_governor.hpp"

#include <gtest/gtest.h>
#include <omp.h>

using bedforge::ThreadGovernor;

namespace {

// A machine of two cores where `others` tasks besides ours want them, and where an iteration
// costs `all` s on two threads and `one` s on one: the clock advances by the cost of each
// iteration at the governor's current thread count.
struct FakeMachine {
  int others = 0;
  double all = 1e-3, one = 1e-3, clock = 0.0;
  ThreadGovernor governor{2, 2, {[this] { return others + governor.threads(); }, [this] { return clock; }}};

  // Runs `seconds` of iterations; the number of them spent on one thread.
  long run(double seconds) {
    long single = 0;
    for (const double end = clock + seconds; clock < end;) {
      single += governor.threads() == 1;
      clock += governor.threads() == 1 ? one : all;
      governor.tick();
    }
    return single;
  }
};

}  // namespace

TEST(ThreadGovernor, AQuietMachineKeepsEveryThreadAndIsNeverProbed) {
  FakeMachine m;
  m.one = 0.1e-3;  // even were one thread faster: with no other load, there is no look
  m.run(10.0);
  EXPECT_EQ(m.governor.threads(), 2);
  EXPECT_EQ(m.governor.probes(), 0);
  EXPECT_EQ(m.governor.iterations_on_one_thread(), 0);
}

TEST(ThreadGovernor, UnderLoadOneThreadIsChosenWhenFasterAndAllAgainWhenTheLoadEnds) {
  const int before = omp_get_max_threads();
  {
    FakeMachine m;
    m.others = 2, m.all = 2.5e-3, m.one = 1e-3;  // measured shape: N = 2000 under two compilers, 11 s against 5.5 s
    const long single = m.run(20.0);
    EXPECT_EQ(m.governor.threads(), 1);
    EXPECT_GT(m.governor.probes(), 5);
    EXPECT_EQ(omp_get_max_threads(), 1);  // what the packer's parallel loops will use
    // Time at the slower count is only the probes: two windows' worth of iterations a second.
    EXPECT_GT(static_cast<double>(single) * m.one, 0.6 * 20.0);
    m.others = 0;
    m.run(2.0);
    EXPECT_EQ(m.governor.threads(), 2);
  }
  EXPECT_EQ(omp_get_max_threads(), before);  // restored on destruction
}

TEST(ThreadGovernor, UnderLoadAllThreadsStayWhenOneIsNotClearlyFaster) {
  FakeMachine m;
  m.others = 1, m.all = 1e-3, m.one = 0.9e-3;  // 10 % faster: inside the margin
  m.run(10.0);
  EXPECT_EQ(m.governor.threads(), 2);
  EXPECT_GT(m.governor.probes(), 5);
}

TEST(ThreadGovernor, OneThreadAllowedMeansNothingToChoose) {
  ThreadGovernor g(1, 2, {[] { return 10; }, [] { return 0.0; }});
  for (int i = 0; i < 100; ++i) g.tick();
  EXPECT_EQ(g.threads(), 1);
  EXPECT_EQ(g.probes(), 0);
}
