// How running a case fails: a solve that diverged is told apart from a step that failed. The
// case's Allrun is a stand-in script that writes the logs OpenFOAM would, so no OpenFOAM runs.
#include "cases/case_runner.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

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
