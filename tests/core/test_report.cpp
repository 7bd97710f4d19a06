#include "core/report.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
namespace fs = std::filesystem;

TEST(Report, StagesAccumulateInTheDirectory) {
  const fs::path d = test_support::fresh_dir("report");
  Report first = Report::load_or_new(d);
  first.set_provenance("1.2.3", {{"particles", {{"count", 3}}}}, 7);
  first.set_stage("pack", {{"summary", "pack: fine"}, {"time_s", 1.0}});
  first.save(d);
  Report second = Report::load_or_new(d);
  second.set_stage("analysis", {{"summary", "analysis: fine"}, {"time_s", 0.5}});
  second.save(d);
  const auto j = Report::load_or_new(d).data();
  EXPECT_EQ(j["seed"], 7);
  EXPECT_EQ(j["bedforge_version"], "1.2.3");
  EXPECT_EQ(j["summary"]["pack"], "pack: fine");
  EXPECT_EQ(j["summary"]["analysis"], "analysis: fine");
}

TEST(Report, CorruptReportIsNamed) {
  const fs::path d = test_support::fresh_dir("corrupt_report", true);
  std::ofstream(d / "report.json") << "{ not json";
  try {
    Report::load_or_new(d);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("report.json"), std::string::npos);
  }
}
