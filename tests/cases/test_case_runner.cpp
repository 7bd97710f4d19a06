// How running a case fails: a solve that diverged is told apart from a step that failed. The
// case's Allrun is a stand-in script that writes the logs OpenFOAM would, so no OpenFOAM runs.
#include "cases/case_runner.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using namespace bedforge;

namespace {

// A case directory whose Allrun writes `solver_log` to log.simpleFoam and fails as
// OpenFOAM's Allrun does when a step fails.
cases::CaseInfo failing_case(const std::string& name, const std::string& solver_log) {
  const fs::path dir = test_support::fresh_dir(name);
  fs::create_directories(dir);
  std::ofstream(dir / "log.simpleFoam") << solver_log;
  std::ofstream(dir / "Allrun") << "#!/bin/sh\necho 'running simpleFoam'\necho 'simpleFoam failed, see log.simpleFoam' >&2\n"
                                   "exit 1\n";
  fs::permissions(dir / "Allrun", fs::perms::owner_all);
  cases::CaseInfo c;
  c.directory = dir;
  c.params.residual_u = 1e-4;
  return c;
}

const std::string kIterations =
    "Time = 1\n\nsmoothSolver:  Solving for Ux, Initial residual = 1, Final residual = 0.01, No Iterations 2\n"
    "GAMG:  Solving for p, Initial residual = 1, Final residual = 0.01, No Iterations 3\nExecutionTime = 1 s\n\n"
    "Time = 2\n\nsmoothSolver:  Solving for Ux, Initial residual = 0.5, Final residual = 0.01, No Iterations 2\n"
    "GAMG:  Solving for p, Initial residual = 0.4, Final residual = 0.01, No Iterations 3\nExecutionTime = 2 s\n\n";

}  // namespace

TEST(CaseRunner, ASolveStoppedByAFloatingPointExceptionIsADivergenceNamingItsIteration) {
  const cases::CaseInfo c = failing_case("diverged", kIterations + "Time = 3\n\n#0  Foam::error::printStack(Foam::Ostream&)\n"
                                                                   "#1  Foam::sigFpe::sigHandler(int)\nFloating point exception\n");
  Progress quiet("case", false);
  try {
    cases::run_case(c, quiet);
    FAIL() << "a diverged solve passed";
  } catch (const ConvergenceError& e) {
    EXPECT_NE(std::string(e.what()).find("simpleFoam diverged"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at iteration 3"), std::string::npos) << e.what();  // the one it stopped in
    EXPECT_NE(std::string(e.what()).find("log.simpleFoam"), std::string::npos) << e.what();
  }
}

TEST(CaseRunner, AnotherFailedStepIsNamedWithAllrunsLastWords) {
  const cases::CaseInfo c = failing_case("failed_step", "--> FOAM FATAL IO ERROR: keyword div(phi,U) is undefined\n");
  Progress quiet("case", false);
  try {
    cases::run_case(c, quiet);
    FAIL() << "a failed step passed";
  } catch (const ConvergenceError& e) {
    FAIL() << "a failed step was called a divergence: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("simpleFoam failed, see log.simpleFoam"), std::string::npos) << e.what();
  }
}

namespace {

// A simpleFoam log whose iterations have these initial residuals (U's three components alike;
// p solved twice an iteration, the second time a tenth of the first, as with a non-orthogonal
// corrector).
std::string solver_log(const std::vector<std::pair<double, double>>& u_and_p) {
  auto number = [](double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  };
  std::string log = "Starting time loop\n\n";
  for (std::size_t k = 0; k < u_and_p.size(); ++k) {
    const auto [u, p] = u_and_p[k];
    log += "Time = " + std::to_string(k + 1) + "\n\n";
    for (const char* c : {"x", "y", "z"})
      log += std::string("smoothSolver:  Solving for U") + c + ", Initial residual = " + number(u) +
             ", Final residual = 1e-06, No Iterations 2\n";
    log += "GAMG:  Solving for p, Initial residual = " + number(p) + ", Final residual = 1e-07, No Iterations 3\n";
    log += "GAMG:  Solving for p, Initial residual = " + number(p / 10) + ", Final residual = 1e-08, No Iterations 2\n";
    log += "ExecutionTime = " + std::to_string(k + 1) + " s  ClockTime = " + std::to_string(k + 1) + " s\n\n";
  }
  return log;
}

std::optional<cases::Divergence> divergence_in(const std::vector<std::pair<double, double>>& u_and_p) {
  std::istringstream log(solver_log(u_and_p));
  return cases::find_divergence(log, 1e-4, 1e-4);
}

}  // namespace

// The bound kDivergenceRise is 10; a converging solve's residuals rose at most 1.3 times their
// least (56 solves, cases/case_runner.hpp), so such bumps must pass and a rise past 10 must not.
TEST(FindDivergence, AConvergingSolveWithBumpsOfOnePointThreeTimesItsLeastIsNoDivergence) {
  EXPECT_FALSE(divergence_in({{1, 1}, {0.1, 0.01}, {0.02, 0.005}, {0.026, 0.0065}, {0.01, 0.003}, {0.001, 0.0003}}));
}

TEST(FindDivergence, ASolveThatTurnsBackIsFoundAtTheFirstIterationPastTenTimesItsLeast) {
  // U falls to 2.5e-3 at iteration 4, then climbs: 10 times that is passed at iteration 7.
  const auto d = divergence_in({{1, 1}, {0.1, 0.01}, {0.01, 0.003}, {0.0025, 0.001}, {0.005, 0.002}, {0.02, 0.004},
                                {0.03, 0.006}, {0.1, 0.02}});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->field, "U");
  EXPECT_EQ(d->least_step, 4);
  EXPECT_DOUBLE_EQ(d->least, 0.0025);
  EXPECT_EQ(d->step, 7);
  EXPECT_DOUBLE_EQ(d->residual, 0.03);
}

TEST(FindDivergence, PIsReadFromItsFirstSolveOfTheIteration) {
  // p's first solves fall to 1e-3 then reach 2e-2 at iteration 5 (its second solves, a tenth,
  // never pass 10 times the first's least on their own).
  const auto d = divergence_in({{1, 1}, {0.1, 0.01}, {0.05, 0.001}, {0.04, 0.005}, {0.03, 0.02}});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->field, "p");
  EXPECT_EQ(d->least_step, 3);
  EXPECT_EQ(d->step, 5);
}

TEST(FindDivergence, ARiseThatStaysBelowTenTimesTheTargetIsNoise) {
  // Converged far below the target of 1e-4, then up 500 and 50,000 times its least to 5e-6 and
  // 5e-4: neither passes 10 times the target; 5e-3 does.
  EXPECT_FALSE(divergence_in({{1, 1}, {1e-3, 1e-3}, {1e-8, 1e-8}, {5e-6, 5e-6}, {5e-4, 1e-8}}));
  const auto d = divergence_in({{1, 1}, {1e-3, 1e-3}, {1e-8, 1e-8}, {5e-6, 5e-6}, {5e-4, 1e-8}, {5e-3, 1e-8}});
  ASSERT_TRUE(d);
  EXPECT_EQ(d->field, "U");
  EXPECT_EQ(d->step, 6);
}

// The runner's part: a stand-in Allrun writes a diverging log iteration by iteration (0.1 s each)
// and, like simpleFoam, ends after writing its fields once the controlDict says stopAt writeNow;
// it gives up after 100 iterations, so a runner that never stops it fails here instead of hanging.
TEST(CaseRunner, ADivergingSolveIsStoppedWithItsFieldsWrittenAndSaidWhere) {
  const fs::path dir = test_support::fresh_dir("diverging");
  fs::create_directories(dir / "system");
  std::ofstream(dir / "system/controlDict") << "application     simpleFoam;\nstopAt          endTime;\nendTime         3000;\n";
  std::ofstream(dir / "Allrun")
      << "#!/bin/sh\ncd \"$(dirname \"$0\")\"\nr=0.001\nfor i in $(seq 1 100); do\n"
         "  if [ $i -gt 5 ]; then r=$(awk \"BEGIN{print $r*1.5}\"); fi\n"
         "  printf 'Time = %d\\n\\nsmoothSolver:  Solving for Ux, Initial residual = %s, Final residual = 1e-06, No "
         "Iterations 2\\nGAMG:  Solving for p, Initial residual = %s, Final residual = 1e-07, No Iterations 3\\n"
         "ExecutionTime = %d s\\n\\n' $i $r $r $i >> log.simpleFoam\n"
         "  if grep -q '^stopAt *writeNow;' system/controlDict; then mkdir $i; echo End >> log.simpleFoam; exit 0; fi\n"
         "  sleep 0.1\ndone\nexit 0\n";
  fs::permissions(dir / "Allrun", fs::perms::owner_all);
  cases::CaseInfo c;
  c.directory = dir;
  c.params.residual_u = 1e-4;
  Progress quiet("case", false);
  try {
    cases::run_case(c, quiet);
    FAIL() << "a diverging solve passed";
  } catch (const ConvergenceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("simpleFoam diverging: the initial residual of U rose from 1.00e-03 at iteration 1"),
              std::string::npos) << what;
    // 1e-3 x 1.5^6 = 1.1e-2 at iteration 11 is the first past 10 times the least.
    EXPECT_NE(what.find("to 1.14e-02 at iteration 11"), std::string::npos) << what;
    std::ifstream dict(dir / "system/controlDict");
    const std::string text((std::istreambuf_iterator<char>(dict)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("stopAt          writeNow;"), std::string::npos) << text;
    EXPECT_NE(text.find("endTime         3000;"), std::string::npos) << text;  // the rest kept
    // Stopped within a few iterations of the divergence (the runner looks every half second),
    // not at the script's hundredth, and said at which, where its fields are.
    long stopped = 0;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_directory() && entry.path().filename() != "system") stopped = std::stol(entry.path().filename());
    EXPECT_GT(stopped, 10);
    EXPECT_LT(stopped, 40);
    EXPECT_NE(what.find("stopped at iteration " + std::to_string(stopped)), std::string::npos) << what;
  }
}
