// The stability suite: every scene in tests/stability must end in a valid result or a clear
// error, never a crash, a NaN, a hang or a silently wrong bed. A scene's first line says what
// it must give:
//   # expect: ok                      exit 0 and a valid bed (finite, inside the container and
//                                     above the floor, overlaps within the packer's tolerance)
//   # expect: ok same-as OTHER.toml   ... and, in diameters, the bed of OTHER (unit invariance)
//   # expect: error WORD              exit 2 or 3, a message naming WORD, no bed written
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/bed_io.hpp"
#include "support/cli.hpp"

namespace fs = std::filesystem;
using namespace cli_test;

namespace {

const fs::path kSuite = fs::path(BEDFORGE_SOURCE_DIR) / "tests" / "stability";
constexpr double kOverlapTolerance = 1e-4;  // d: the packer's default final tolerance

struct Expectation {
  bool ok = false, error = false;
  std::string word, same_as;
};

Expectation expectation_of(const fs::path& scene) {
  std::ifstream in(scene);
  std::string line;
  std::getline(in, line);
  std::istringstream words(line);
  std::string hash, tag, kind;
  words >> hash >> tag >> kind;
  Expectation e;
  e.ok = kind == "ok";
  e.error = kind == "error";
  std::string next;
  if (words >> next) {
    if (next == "same-as") words >> e.same_as;
    else e.word = next;
  }
  return e;
}

fs::path output_of(const fs::path& scene) { return fs::temp_directory_path() / "bedforge_stability" / scene.stem(); }

// A bed must be finite, inside its container and above the floor; `tolerance_d` of the
// smallest diameter is allowed for the packer's own overlap tolerance.
void expect_valid_bed(const fs::path& dir, const std::string& name) {
  const bedforge::ImportedBed in = bedforge::read_bed_text(dir / "bed.csv", 1.0);
  ASSERT_TRUE(in.bed.container) << name;
  double d_min = in.bed.diameters.front();
  for (double d : in.bed.diameters) d_min = std::min(d_min, d);
  for (std::size_t i = 0; i < in.bed.size(); ++i) {
    const auto& c = in.bed.centres[i];
    const double r = 0.5 * in.bed.diameters[i];
    ASSERT_TRUE(c.allFinite()) << name << ": sphere " << i;
    EXPECT_GE(c.z() - r, -kOverlapTolerance * d_min) << name << ": sphere " << i << " below the floor";
    bedforge::WallContact walls[bedforge::Container::kMaxWallContacts];
    const int nw = in.bed.container->wall_contacts(c, r, walls);
    for (int k = 0; k < nw; ++k)
      EXPECT_LE(walls[k].overlap, kOverlapTolerance * d_min) << name << ": sphere " << i << " in the wall";
  }
  // JSON keeps a NaN as null, so look where it shows as text: the stages' summary lines.
  const auto report = nlohmann::json::parse(read(dir / "report.json"));
  const std::regex not_a_number(R"(\b(nan|inf)\b)", std::regex::icase);
  for (const auto& [stage, line] : report["summary"].items())
    EXPECT_FALSE(std::regex_search(line.get<std::string>(), not_a_number)) << name << ", " << stage << ": " << line;
  // Pair overlaps counted here, not taken from the packer's report: a sweep along z over pairs
  // closer in height than the largest diameter, periodic sides by their minimum image.
  std::vector<std::size_t> order(in.bed.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return in.bed.centres[a].z() < in.bed.centres[b].z(); });
  const double d_max = *std::max_element(in.bed.diameters.begin(), in.bed.diameters.end());
  const bedforge::Periodicity periodic = in.bed.container->periodicity();
  double worst = 0.0;
  for (std::size_t a = 0; a < order.size(); ++a)
    for (std::size_t b = a + 1; b < order.size(); ++b) {
      const std::size_t i = order[a], j = order[b];
      if (in.bed.centres[j].z() - in.bed.centres[i].z() > d_max) break;
      const double gap = periodic.separation(in.bed.centres[i], in.bed.centres[j]).norm() -
                         0.5 * (in.bed.diameters[i] + in.bed.diameters[j]);
      worst = std::max(worst, -gap / d_min);
    }
  // A packed bed keeps within the packer's tolerance; an imported bed keeps its file's overlaps
  // (that is the input under test), and then the treated surface must be valid.
  if (report["stages"]["pack"].value("algorithm", "") != "import") {
    EXPECT_LE(worst, kOverlapTolerance) << name;
  }
  if (report["stages"].contains("surface")) {
    const auto& check = report["stages"]["surface"]["check"];
    EXPECT_TRUE(check["closed"].get<bool>() && check["manifold"].get<bool>()) << name << ": " << check.dump();
    EXPECT_FALSE(check.value("self_intersections", true)) << name << ": " << check.dump();
  }
}

std::vector<fs::path> suite() {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(kSuite))
    if (e.path().extension() == ".toml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

class StabilityScene : public ::testing::TestWithParam<fs::path> {};

}  // namespace

TEST_P(StabilityScene, EndsInAValidBedOrAClearError) {
  const fs::path scene = GetParam();
  const std::string name = scene.filename().string();
#ifndef BEDFORGE_HAVE_CGAL
  if (read(scene).find("\"stl\"") != std::string::npos) GTEST_SKIP() << name << " needs the surface stage (CGAL)";
#endif
  const Expectation e = expectation_of(scene);
  ASSERT_TRUE(e.ok || e.error) << name << ": its first line must be '# expect: ok|error ...'";
  const fs::path dir = output_of(scene);
  fs::remove_all(dir);
  // A hang is a failure too: timeout exits with 124.
  const Result r = shell("timeout 600 " + std::string(BEDFORGE_BINARY) + " --quiet run " + scene.string() + " -o " +
                         dir.string());
  ASSERT_NE(r.status, 124) << name << " hung";
  if (r.status == 0) {
    ASSERT_TRUE(e.ok) << name << " should have been refused (" << e.word << "):\n" << r.output;
    expect_valid_bed(dir, name);
  } else {
    ASSERT_TRUE(e.error) << name << " failed:\n" << r.output;
    EXPECT_TRUE(r.status == 2 || r.status == 3) << name << ": exit " << r.status << "\n" << r.output;
    EXPECT_NE(r.output.find(e.word), std::string::npos) << name << ": the message should name " << e.word << "\n"
                                                        << r.output;
    EXPECT_FALSE(fs::exists(dir / "bed.csv")) << name << " left a bed behind";
  }
}

INSTANTIATE_TEST_SUITE_P(Suite, StabilityScene, ::testing::ValuesIn(suite()),
                         [](const ::testing::TestParamInfo<fs::path>& info) {
                           std::string s = info.param.stem().string();
                           for (char& c : s)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return s;
                         });

// d = 1e-6 m and d = 1 m must give the same bed in diameters: the packer works in units of the
// diameter, and no absolute tolerance may creep in.
TEST(StabilityUnits, TinyAndHugeDiametersGiveTheSameBedInDiameters) {
  for (const fs::path& scene : suite()) {
    const Expectation e = expectation_of(scene);
    if (e.same_as.empty()) continue;
    // Own folders: ctest runs the suite's scenes beside this test.
    auto out = [](const fs::path& s) { return output_of(s).string() + "_units"; };
    for (const fs::path& s : {scene, kSuite / e.same_as}) {
      fs::remove_all(out(s));
      ASSERT_EQ(cli_test::bedforge("--quiet run " + s.string() + " -o " + out(s)).status, 0) << s;
    }
    const auto a = bedforge::read_bed_text(fs::path(out(scene)) / "bed.csv", 1.0).bed;
    const auto b = bedforge::read_bed_text(fs::path(out(kSuite / e.same_as)) / "bed.csv", 1.0).bed;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Eigen::Vector3d pa = a.centres[i] / a.diameters[i], pb = b.centres[i] / b.diameters[i];
      EXPECT_LT((pa - pb).norm(), 1e-9) << scene.filename() << " sphere " << i;
    }
  }
}
