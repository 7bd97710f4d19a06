// How running a case fails: a solve that diverged is told apart from a step that failed. The
// case's Allrun is a stand-in script that writes the logs OpenFOAM would, so no OpenFOAM runs.
#include "cases/case_runner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
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

// One iteration of a simpleFoam log, `step`, with these initial residuals (U's three components
// alike; p solved twice, the second time a tenth of the first, as with a non-orthogonal corrector).
std::string iteration_text(std::size_t step, double u, double p) {
  auto number = [](double x) {
    std::ostringstream s;
    s << x;
    return s.str();
  };
  std::string text = "Time = " + std::to_string(step) + "\n\n";
  for (const char* c : {"x", "y", "z"})
    text += std::string("smoothSolver:  Solving for U") + c + ", Initial residual = " + number(u) +
            ", Final residual = 1e-06, No Iterations 2\n";
  text += "GAMG:  Solving for p, Initial residual = " + number(p) + ", Final residual = 1e-07, No Iterations 3\n";
  text += "GAMG:  Solving for p, Initial residual = " + number(p / 10) + ", Final residual = 1e-08, No Iterations 2\n";
  return text + "ExecutionTime = " + std::to_string(step) + " s  ClockTime = " + std::to_string(step) + " s\n\n";
}

// A simpleFoam log whose iterations 1, 2, ... have these initial residuals of U and p.
std::string solver_log(const std::vector<std::pair<double, double>>& u_and_p) {
  std::string log = "Starting time loop\n\n";
  for (std::size_t k = 0; k < u_and_p.size(); ++k) log += iteration_text(k + 1, u_and_p[k].first, u_and_p[k].second);
  return log;
}

std::optional<cases::Divergence> divergence_in(const std::vector<std::pair<double, double>>& u_and_p) {
  std::istringstream log(solver_log(u_and_p));
  return cases::find_divergence(log, 1e-4, 1e-4);
}

const std::string kIterations = solver_log({{1, 1}, {0.5, 0.4}});

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
  c.params.residual_u = c.params.residual_p = 1e-4;
  return c;
}

// A stand-in Allrun in `dir` (with its system/controlDict): iteration i of `count` appends
// iterations/i to log.simpleFoam and runs the shell lines `also`, then, like simpleFoam, ends with
// its fields written (a directory named i) once the controlDict says stopAt writeNow; `pause`
// seconds between iterations. Run to the end, it stops nowhere.
void write_stand_in_allrun(const fs::path& dir, int count, const std::string& also, const std::string& pause) {
  std::ofstream(dir / "system/controlDict") << "application     simpleFoam;\nstopAt          endTime;\nendTime         3000;\n";
  std::ofstream(dir / "Allrun")
      << "#!/bin/sh\ncd \"$(dirname \"$0\")\"\npp=postProcessing\nfor i in $(seq 1 " << count << "); do\n"
      << "  cat iterations/$i >> log.simpleFoam\n" << also
      << "  if grep -q '^stopAt *writeNow;' system/controlDict; then mkdir $i; echo End >> log.simpleFoam; exit 0; fi\n"
      << "  sleep " << pause << "\ndone\nexit 0\n";
  fs::permissions(dir / "Allrun", fs::perms::owner_all);
}

// The iteration a stand-in Allrun was stopped at (the directory of its fields), 0 if it ran out.
long stopped_at(const fs::path& dir) {
  long stopped = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory() && std::isdigit(static_cast<unsigned char>(entry.path().filename().string()[0])))
      stopped = std::stol(entry.path().filename());
  return stopped;
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

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

// A log read while it is written: an iteration cut off at the end of the file is left for the
// next look, and each is read once, so that reading the log in parts finds what reading it whole
// does (ASolveThatTurnsBack...'s log, divergent at iteration 7).
TEST(DivergenceWatch, FollowingALogAsItGrowsFindsWhatTheWholeLogShows) {
  const std::string whole = solver_log({{1, 1}, {0.1, 0.01}, {0.01, 0.003}, {0.0025, 0.001}, {0.005, 0.002},
                                        {0.02, 0.004}, {0.03, 0.006}, {0.1, 0.02}});
  const fs::path dir = test_support::fresh_dir("following"), path = dir / "log.simpleFoam";
  fs::create_directories(dir);
  cases::DivergenceWatch watch(1e-4, 1e-4);
  EXPECT_FALSE(watch.follow(path));  // no log yet
  // Up to the middle of iteration 7's U line: its residual 0.03 is not read yet.
  const std::size_t cut = whole.find("Initial residual = 0.03");
  std::ofstream(path) << whole.substr(0, cut);
  EXPECT_FALSE(watch.follow(path));
  EXPECT_FALSE(watch.follow(path));  // nothing added: nothing new
  // The rest of iteration 7: finished only when iteration 8 begins.
  const std::size_t eighth = whole.find("Time = 8");
  std::ofstream(path, std::ios::app) << whole.substr(cut, eighth - cut);
  EXPECT_FALSE(watch.follow(path));
  std::ofstream(path, std::ios::app) << whole.substr(eighth);
  const auto d = watch.follow(path);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->least_step, 4);
  EXPECT_EQ(d->step, 7);
  EXPECT_DOUBLE_EQ(d->residual, 0.03);
}

// The runner's part: a stand-in Allrun appends a diverging log iteration by iteration (0.1 s each;
// U and p at 1e-3 to iteration 5, then 1.5 times more each) and, like simpleFoam, ends after
// writing its fields once the controlDict says stopAt writeNow; it gives up after 100 iterations,
// so a runner that never stops it fails here instead of hanging.
TEST(CaseRunner, ADivergingSolveIsStoppedWithItsFieldsWrittenAndSaidWhere) {
  const fs::path dir = test_support::fresh_dir("diverging");
  fs::create_directories(dir / "system");
  fs::create_directories(dir / "iterations");
  for (int i = 1; i <= 100; ++i) {
    const double r = 1e-3 * std::pow(1.5, std::max(0, i - 5));
    std::ofstream(dir / "iterations" / std::to_string(i)) << iteration_text(i, r, r);
  }
  write_stand_in_allrun(dir, 100, "", "0.1");
  cases::CaseInfo c;
  c.directory = dir;
  c.params.residual_u = c.params.residual_p = 1e-4;
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
    const std::string text = text_of(dir / "system/controlDict");
    EXPECT_NE(text.find("stopAt          writeNow;"), std::string::npos) << text;
    EXPECT_NE(text.find("endTime         3000;"), std::string::npos) << text;  // the rest kept
    // Stopped within a few iterations of the divergence (the runner looks every half second),
    // not at the script's hundredth, and said at which, where its fields are.
    const long stopped = stopped_at(dir);
    EXPECT_GT(stopped, 10);
    EXPECT_LT(stopped, 40);
    EXPECT_NE(what.find("stopped at iteration " + std::to_string(stopped)), std::string::npos) << what;
  }
}

namespace {

// A stand-in Allrun for a solve past its residual targets: iteration i (0.05 s each, up to 150)
// appends its log text (U and p at 1e-3 until iteration `reached`, 1e-5 from there) and its
// monitors' rows, the kinematic pressure on the section's lower plane 1 + 0.1 decay^i, 0 on the
// upper one a metre above, so that dp/L (density 1) settles to 1 Pa/m geometrically; like
// simpleFoam it ends with its fields written once the controlDict says stopAt writeNow.
cases::CaseInfo settling_case(const std::string& name, int reached, double decay) {
  const fs::path dir = test_support::fresh_dir(name);
  for (const char* d : {"system", "iterations", "bottom", "postProcessing/pBedBottom/0", "postProcessing/pBedTop/0",
                        "postProcessing/flowRate/0", "postProcessing/pInlet/0", "postProcessing/pOutlet/0",
                        "postProcessing/forceInlet/0", "postProcessing/forceOutlet/0"})
    fs::create_directories(dir / d);
  for (int i = 1; i <= 150; ++i) {
    const double r = i < reached ? 1e-3 : 1e-5;
    std::ofstream(dir / "iterations" / std::to_string(i)) << iteration_text(i, r, r);
    std::ofstream(dir / "bottom" / std::to_string(i)) << i << '\t' << std::setprecision(12) << 1.0 + 0.1 * std::pow(decay, i)
                                                      << '\n';
  }
  std::ofstream(dir / "postProcessing/pInlet/0/surfaceFieldValue.dat") << "# Time areaAverage(p)\n1\t1\n";
  std::ofstream(dir / "postProcessing/pOutlet/0/surfaceFieldValue.dat") << "# Time areaAverage(p)\n1\t0\n";
  for (const char* f : {"forceInlet", "forceOutlet"})
    std::ofstream(dir / "postProcessing" / f / "0/force.dat") << "# Time total pressure viscous\n1\t(0 0 0)\t(0 0 0)\t(0 0 0)\n";
  write_stand_in_allrun(dir, 150,
                        "  cat bottom/$i >> $pp/pBedBottom/0/surfaceFieldValue.dat\n"
                        "  printf '%s\\t0\\n' $i >> $pp/pBedTop/0/surfaceFieldValue.dat\n"
                        "  printf '%s\\t1\\n' $i >> $pp/flowRate/0/surfaceFieldValue.dat\n",
                        "0.05");
  cases::CaseInfo c;
  c.directory = dir;
  c.params.residual_u = c.params.residual_p = 1e-4;
  c.params.density_kg_m3 = 1.0;
  c.velocity_m_s = 1.0;
  c.inlet_area_m2 = 1.0;  // the flow rate of 1 m3/s the monitor says
  c.section.z_low = 0.0;
  c.section.z_high = 1.0;
  c.walls = false;
  c.exact_pressure_gradient_pa_m = 1.0;
  return c;
}

}  // namespace

// dp/L = 1 + 0.1 x 0.9^i after the targets are reached at iteration 30: 0.1 x 0.9^i is within the
// tolerance of 1e-3 from iteration 44 on, where the runner must stop the solve (it looks every
// half second, 10 iterations here), not at the targets and not at the script's end.
TEST(CaseRunner, PastItsResidualTargetsASolveRunsOnUntilDpLHasSettledToTheTolerance) {
  const cases::CaseInfo c = settling_case("settling", 30, 0.9);
  Progress quiet("case", false);
  const cases::FlowResult r = cases::run_case(c, quiet);
  const long stopped = stopped_at(c.directory);
  EXPECT_GE(stopped, 44);
  EXPECT_LT(stopped, 60);  // the run-on limit, twice the 30 iterations to the targets
  EXPECT_EQ(r.stopped_by, "settled");
  EXPECT_TRUE(r.converged);
  EXPECT_LE(std::abs(r.pressure_gradient_bed_pa_m - 1.0), 1e-3);
  ASSERT_TRUE(r.pressure_gradient_iteration);
  EXPECT_LE(std::abs(r.pressure_gradient_iteration->remaining), 1e-3);
  // The controlDict as written again, so that Allrun run by hand solves to its end.
  const std::string dict = text_of(c.directory / "system/controlDict");
  EXPECT_NE(dict.find("stopAt          endTime;"), std::string::npos) << dict;
  EXPECT_NE(dict.find("endTime         3000;"), std::string::npos) << dict;
}

// dp/L = 1 + 0.1 x 0.99^i settles too slowly (still 5 % to go at iteration 60): the solve stops
// once it has run as many iterations past its targets (reached at 30) as it took to reach them,
// and says so, with the iteration error it leaves.
TEST(CaseRunner, ASolveThatDoesNotSettleStopsAfterAsManyIterationsAgainAndSaysSo) {
  const cases::CaseInfo c = settling_case("not_settling", 30, 0.99);
  Progress quiet("case", false);
  const cases::FlowResult r = cases::run_case(c, quiet);
  const long stopped = stopped_at(c.directory);
  EXPECT_GE(stopped, 60);
  EXPECT_LT(stopped, 100);
  EXPECT_EQ(r.stopped_by, "run_on_limit");
  EXPECT_TRUE(r.converged);
  ASSERT_TRUE(r.pressure_gradient_iteration);
  EXPECT_GT(std::abs(r.pressure_gradient_iteration->remaining), 1e-2);
}
