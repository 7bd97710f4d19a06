// The bedforge program as a user runs it: outputs, provenance, and bad input.
#include <Eigen/Core>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "support/cli.hpp"

namespace fs = std::filesystem;
using namespace cli_test;

namespace {

fs::path scene(const std::string& name, const std::string& text) {
  const fs::path p = fresh_dir("scenes") / name;
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
  return p;
}

// Bad input: exit status 2, a message naming `key`, and nothing written.
void expect_rejected(const std::string& args, const std::string& key) {
  const fs::path out = fresh_dir("rejected");
  const Result r = bedforge(args + " -o " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(key), std::string::npos) << "message does not name " << key << ": " << r.output;
  EXPECT_FALSE(fs::exists(out)) << "output written for rejected input " << args;
}

}  // namespace

TEST(CommandLine, PackWritesBedReportSceneAndRecordsProvenance) {
  const fs::path out = fresh_dir("pack");
  const Result r = bedforge("pack --aspect-ratio 3 --count 40 --seed 5 --diameter-m 0.002 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("pack (soft-sphere accelerated): 40 spheres"), std::string::npos) << r.output;
  for (const char* f : {"bed.csv", "bed.vtp", "report.json", "summary.txt", "scene.toml"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const std::string csv = read(out / "bed.csv");
  EXPECT_NE(csv.find("# version: "), std::string::npos);
  EXPECT_NE(csv.find("# seed: 5"), std::string::npos);
  EXPECT_NE(csv.find("\"diameter\":0.006"), std::string::npos) << "container not recorded in metres";
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  EXPECT_EQ(report["seed"], 5);
  EXPECT_EQ(report["scene"]["particles"]["count"], 40);
  EXPECT_FALSE(report["bedforge_version"].get<std::string>().empty());
  const auto& pack = report["stages"]["pack"];
  for (const char* k : {"iterations", "time_s", "max_pair_overlap_d", "force_residual_rms", "void_fraction", "summary",
                        "peak_memory_mb"})
    EXPECT_TRUE(pack.contains(k)) << k;
  // The human summary beside the JSON: the version and seed, then the stage's printed line.
  const std::string summary = read(out / "summary.txt");
  EXPECT_NE(summary.find(report["bedforge_version"].get<std::string>() + ", seed 5"), std::string::npos) << summary;
  EXPECT_NE(summary.find(pack["summary"].get<std::string>()), std::string::npos) << summary;
  EXPECT_NE(r.output.find(pack["summary"].get<std::string>()), std::string::npos) << r.output;
  // The same command gives the same bed.
  const fs::path again = fresh_dir("pack_again");
  ASSERT_EQ(bedforge("pack --aspect-ratio 3 --count 40 --seed 5 --diameter-m 0.002 -o " + again.string()).status, 0);
  EXPECT_EQ(read(again / "bed.csv"), csv);
}

TEST(CommandLine, AnalyseAddsItsStageToTheDirectory) {
  const fs::path out = fresh_dir("analyse");
  ASSERT_EQ(bedforge("pack --aspect-ratio 4 --count 120 -o " + out.string()).status, 0);
  const Result r = bedforge("analyse " + out.string() + " --radial-bin-d 0.1");
  ASSERT_EQ(r.status, 0) << r.output;
  for (const char* f : {"radial_profile.csv", "axial_profile.csv", "centre_distribution.csv", "contacts.csv"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  EXPECT_TRUE(report["stages"].contains("pack"));
  EXPECT_DOUBLE_EQ(report["stages"]["analysis"]["parameters"]["radial_bin_d"].get<double>(), 0.1);
  EXPECT_TRUE(report["summary"].contains("analysis"));
}

TEST(CommandLine, RunFollowsTheScenesOutputs) {
  const fs::path only_positions = fresh_dir("run_positions");
  const auto s = scene("positions.toml",
                       "[container]\ndiameter_d = 3\n[particles]\ncount = 30\n[outputs]\nfiles = [\"positions\"]\n");
  ASSERT_EQ(bedforge("run " + s.string() + " -o " + only_positions.string()).status, 0);
  EXPECT_TRUE(fs::exists(only_positions / "bed.csv"));
  EXPECT_FALSE(fs::exists(only_positions / "bed.vtp"));
  EXPECT_FALSE(fs::exists(only_positions / "radial_profile.csv"));
  const auto report = nlohmann::json::parse(read(only_positions / "report.json"));
  EXPECT_FALSE(report["stages"].contains("analysis"));
}

TEST(CommandLine, EveryShippedSceneRuns) {
  std::set<std::string> with_a_case;  // each has a test in tests/cases or tests/pipeline
  for (const auto& e : fs::recursive_directory_iterator(fs::path(BEDFORGE_SOURCE_DIR) / "scenes")) {
    if (e.path().extension() != ".toml") continue;
#ifndef BEDFORGE_HAVE_CGAL
    std::stringstream text;
    text << std::ifstream(e.path()).rdbuf();
    if (text.str().find("[contacts]") != std::string::npos) continue;  // needs the surface stage
#endif
    {
      std::stringstream text;
      text << std::ifstream(e.path()).rdbuf();
      if (text.str().find("\"case\"]") != std::string::npos) {
        with_a_case.insert(e.path().filename().string());
        continue;
      }
    }
    const fs::path out = fresh_dir("scene_" + e.path().stem().string());
    // The Monte Carlo schedule cut short (the validation tool runs it in full); the options only
    // set keys of [packing.monte_carlo], so soft-sphere scenes run as shipped.
    const Result r = bedforge("--quiet run " + e.path().string() + " -o " + out.string() +
                              " --mixing-cycles 100 --shakes 1 --settling-cycles 100");
    EXPECT_EQ(r.status, 0) << e.path() << ": " << r.output;
    EXPECT_TRUE(fs::exists(out / "report.json")) << e.path();
  }
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // A new example that makes a case needs a test of its own there.
  EXPECT_EQ(with_a_case, (std::set<std::string>{"default.toml", "small_bed_flow.toml", "box_bed_flow.toml",
                                                "empty_tube_verification.toml", "simple_cubic_verification.toml",
                                                "periodic_section_flow.toml", "periodic_cubic_verification.toml",
                                                "periodic_box_cubic_verification.toml", "random_array_stokes.toml",
                                                "touching_cubic_bridged.toml", "layered_bed_accuracy.toml"}));
#endif
}

TEST(CommandLine, ImportedBedIsAnalysed) {
  const fs::path packed = fresh_dir("to_import"), out = fresh_dir("imported");
  ASSERT_EQ(bedforge("pack --aspect-ratio 4 --count 80 --diameter-m 0.001 -o " + packed.string()).status, 0);
  // Rewrite as a DEM code would: millimetres, spaces, a column line, no container record.
  std::ifstream in(packed / "bed.csv");
  fs::create_directories(out.parent_path());
  std::ofstream dem(out.parent_path() / "dem.txt");
  dem << "x y z diameter\n";
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 'x') continue;
    std::stringstream row(line);
    double v[4];
    char comma;
    row >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
    dem << v[0] * 1e3 << ' ' << v[1] * 1e3 << ' ' << v[2] * 1e3 << ' ' << v[3] * 1e3 << '\n';
  }
  dem.close();
  const Result r = bedforge("import " + (out.parent_path() / "dem.txt").string() +
                            " --units mm --container-diameter-m 0.004 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("import: 80 spheres"), std::string::npos) << r.output;
  ASSERT_EQ(bedforge("analyse " + out.string()).status, 0);
  const auto a = nlohmann::json::parse(read(out / "report.json"))["stages"]["analysis"];
  EXPECT_LT(a["overlaps"]["max_pair_overlap_d"].get<double>(), 1e-3);  // printed with 6 digits
}

// A bed packed here, written out as LIGGGHTS would (millimetres, the container axis at x = 50 mm,
// radius column), comes back as the same bed: same void fraction, same overlaps. With the
// origin left out its spheres lie outside the container, which is refused by name.
TEST(CommandLine, LiggghtsDumpIsImportedIntoTheSameBed) {
  const fs::path packed = fresh_dir("to_dump"), out = fresh_dir("from_dump"), wrong = fresh_dir("from_dump_wrong");
  ASSERT_EQ(bedforge("pack --aspect-ratio 4 --count 60 --diameter-m 0.002 -o " + packed.string()).status, 0);
  std::ifstream in(packed / "bed.csv");
  std::vector<std::array<double, 4>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 'x') continue;
    std::array<double, 4> v;
    char comma;
    std::stringstream(line) >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
    rows.push_back(v);
  }
  const fs::path dump = out.parent_path() / "bed.liggghts";
  std::ofstream d(dump);
  d << "ITEM: TIMESTEP\n200000\nITEM: NUMBER OF ATOMS\n" << rows.size() << "\nITEM: BOX BOUNDS ff ff ff\n";
  d << "40 60\n-10 10\n0 30\nITEM: ATOMS id type x y z vx vy vz radius\n";
  d.precision(17);
  for (std::size_t i = 0; i < rows.size(); ++i)
    d << i + 1 << " 1 " << rows[i][0] * 1e3 + 50.0 << ' ' << rows[i][1] * 1e3 << ' ' << rows[i][2] * 1e3 << " 0 0 0 "
      << rows[i][3] * 0.5e3 << '\n';
  d.close();
  const Result r = bedforge("import " + dump.string() + " --format lammps-dump --units mm --origin-m 0.05 0 0 " +
                            "--container-diameter-m 0.008 -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto original = nlohmann::json::parse(read(packed / "report.json"))["stages"]["pack"];
  const auto imported = nlohmann::json::parse(read(out / "report.json"))["stages"]["pack"];
  EXPECT_EQ(imported["spheres"], 60);
  EXPECT_EQ(imported["header"]["timestep"], 200000);
  EXPECT_NEAR(imported["void_fraction"]["whole_bed"].get<double>(), original["void_fraction"]["whole_bed"].get<double>(),
              1e-9);
  EXPECT_NEAR(imported["overlaps"]["max_pair_overlap_d"].get<double>(), original["max_pair_overlap_d"].get<double>(),
              1e-6);

  const Result bad = bedforge("import " + dump.string() + " --format lammps-dump --units mm " +
                              "--container-diameter-m 0.008 -o " + wrong.string());
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.output.find("lies outside the cylinder"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("packing.origin_m"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(wrong / "bed.csv"));
}

// A bed periodic on every side (a box section, 1 mm spheres), written as a LAMMPS dump of a
// periodic box [0, 5] mm in each direction with every third centre unwrapped a period below,
// comes back as the same bed: the container from the dump's box, the same void fraction and
// overlaps; no centre is refused as below a floor the section does not have.
TEST(CommandLine, PeriodicLammpsBoxIsImportedIntoTheSameBed) {
  const fs::path packed = fresh_dir("periodic_to_dump"), out = fresh_dir("periodic_from_dump");
  const fs::path box = scene("periodic_box.toml", "[container]\ntype = \"box\"\nsize_x_d = 5\nsize_y_d = 5\nperiodic_x = true\n"
                          "periodic_y = true\nperiod_z_d = 5\n[particles]\ncount = 120\ndiameter_m = 0.001\n");
  const Result run = bedforge("run " + box.string() + " -o " + packed.string());
  ASSERT_EQ(run.status, 0) << run.output;
  std::ifstream in(packed / "bed.csv");
  const fs::path dump = out.parent_path() / "periodic.dump";
  std::ofstream d(dump);
  std::vector<std::string> atoms;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 'x') continue;
    std::array<double, 4> v;
    char comma;
    std::stringstream(line) >> v[0] >> comma >> v[1] >> comma >> v[2] >> comma >> v[3];
    std::ostringstream row;
    row.precision(17);
    const double unwrap = atoms.size() % 3 == 0 ? 5.0 : 0.0;
    row << atoms.size() + 1 << " 1 " << v[0] * 1e3 + 2.5 << ' ' << v[1] * 1e3 + 2.5 << ' ' << v[2] * 1e3 - unwrap << ' '
        << v[3] * 0.5e3;
    atoms.push_back(row.str());
  }
  d << "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n" << atoms.size() << "\nITEM: BOX BOUNDS pp pp pp\n0 5\n0 5\n0 5\n"
    << "ITEM: ATOMS id type x y z radius\n";
  for (const auto& a : atoms) d << a << '\n';
  d.close();
  const Result r = bedforge("import " + dump.string() + " --format lammps-dump --units mm -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto original = nlohmann::json::parse(read(packed / "report.json"))["stages"]["pack"];
  const auto imported = nlohmann::json::parse(read(out / "report.json"))["stages"]["pack"];
  EXPECT_EQ(imported["spheres"], 120);
  EXPECT_NEAR(imported["void_fraction"]["whole_bed"].get<double>(), original["void_fraction"]["whole_bed"].get<double>(),
              1e-9);
  EXPECT_NEAR(imported["void_fraction"]["axial_period_m"].get<double>(), 0.005, 1e-15);
  EXPECT_NEAR(imported["overlaps"]["max_pair_overlap_d"].get<double>(), original["max_pair_overlap_d"].get<double>(),
              1e-6);
}

// The sphere rows of a bed.csv (its header records the scene, which may differ).
std::string bed_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string rows;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') rows += line + "\n";
  return rows;
}

// A run into a directory that holds the bed of the same container, particles and packing reuses
// it; a change there packs again, and --force packs again whatever changed, into the same bed.
TEST(CommandLine, UnchangedPackingIsReusedAndForceRepacks) {
  const std::string base =
      "[container]\ndiameter_d = 4\n[particles]\ncount = 50\ndiameter_m = 0.001\n[outputs]\n"
      "files = [\"positions\", \"analysis\"]\n";
  const fs::path dir = fresh_dir("reuse");
  const Result first = bedforge("run " + scene("a.toml", base + "[analysis]\nradial_bin_d = 0.05\n").string() +
                                " -o " + dir.string());
  ASSERT_EQ(first.status, 0) << first.output;
  const std::string rows = bed_rows(dir / "bed.csv");
  const auto key = nlohmann::json::parse(read(dir / "report.json"))["stages"]["pack"]["cache_key"];

  const Result analysis_only = bedforge("run " + scene("b.toml", base + "[analysis]\nradial_bin_d = 0.1\n").string() +
                                        " -o " + dir.string());
  ASSERT_EQ(analysis_only.status, 0) << analysis_only.output;
  EXPECT_NE(analysis_only.output.find("pack: reused"), std::string::npos) << analysis_only.output;
  EXPECT_EQ(bed_rows(dir / "bed.csv"), rows);
  const auto report = nlohmann::json::parse(read(dir / "report.json"));
  EXPECT_EQ(report["stages"]["pack"]["cache_key"], key);
  EXPECT_EQ(report["scene"]["analysis"]["radial_bin_d"], 0.1);  // the analysis ran with the new scene

  const Result forced = bedforge("run " + scene("b.toml", base + "[analysis]\nradial_bin_d = 0.1\n").string() +
                                 " -o " + dir.string() + " --force");
  ASSERT_EQ(forced.status, 0) << forced.output;
  EXPECT_EQ(forced.output.find("pack: reused"), std::string::npos) << forced.output;
  EXPECT_EQ(bed_rows(dir / "bed.csv"), rows);  // same scene and seed: the same bed, bit for bit

  const Result more = bedforge("run " + scene("c.toml", base + "[packing]\nseed = 2\n").string() + " -o " +
                               dir.string());
  ASSERT_EQ(more.status, 0) << more.output;
  EXPECT_EQ(more.output.find("pack: reused"), std::string::npos) << more.output;
  EXPECT_NE(bed_rows(dir / "bed.csv"), rows);
}

TEST(CommandLine, BadInputIsRejectedByName) {
  expect_rejected("pack --aspect-ratio 3 --count 0", "particles.count");
  expect_rejected("pack --aspect-ratio 3 --count -5", "particles.count");
  expect_rejected("pack --aspect-ratio 0.8 --count 10", "container.diameter_d");
  expect_rejected("pack --aspect-ratio 3 --count 10 --diameter-m 0", "particles.diameter_m");
  expect_rejected("pack --count 10", "container.diameter_d");
  expect_rejected("pack --aspect-ratio 3 --count 10 --initial-void-fraction 1.2",
                  "packing.soft_sphere.initial_void_fraction");
  expect_rejected("pack --aspect-ratio 3 --count 10 --mode fast", "packing.soft_sphere.mode");
  expect_rejected("run " + scene("unknown.toml", "[container]\ndiameter_d = 3\ndiamter_d = 4\n[particles]\ncount = 5\n")
                               .string(),
                  "container.diamter_d");
  expect_rejected("run " + scene("nan.toml", "[container]\ndiameter_d = nan\n[particles]\ncount = 5\n").string(),
                  "container.diameter_d");
  expect_rejected("run " + scene("type.toml", "[container]\ndiameter_d = \"wide\"\n[particles]\ncount = 5\n").string(),
                  "container.diameter_d");
  expect_rejected("run " +
                      scene("fractions.toml",
                            "[container]\ndiameter_d = 5\n[particles]\ncount = 5\ndistribution = \"discrete\"\n"
                            "diameters_m = [0.001, 0.002]\nnumber_fractions = [0.5, 0.4]\n")
                          .string(),
                  "particles.number_fractions");
  expect_rejected("run " + scene("section.toml", "[contianer]\ndiameter_d = 3\n").string(), "[contianer]");
  expect_rejected("run " + scene("syntax.toml", "[container\n").string(), "syntax.toml:1");
}

// Checked before any work: an output path that is a file, and a message without raw records.
TEST(CommandLine, AnOutputThatIsAFileIsRefusedBeforePacking) {
  const fs::path file = fresh_dir("file_output");
  fs::create_directories(file.parent_path());
  std::ofstream(file) << "not a directory\n";
  ASSERT_TRUE(fs::is_regular_file(file));
  const Result r = bedforge("pack --aspect-ratio 4 --count 2000 -o " + file.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("is not a directory"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("pack ("), std::string::npos) << "packed first: " << r.output;
  EXPECT_EQ(read(file), "not a directory\n");
  const Result narrow = bedforge("pack --aspect-ratio 0.9 --count 10 -o " + fresh_dir("narrow").string());
  EXPECT_EQ(narrow.status, 2);
  EXPECT_NE(narrow.output.find("it holds spheres up to 0.0009 m, 0.9 d"), std::string::npos) << narrow.output;
  EXPECT_EQ(narrow.output.find('{'), std::string::npos) << "a raw record in the message: " << narrow.output;
}

TEST(CommandLine, DivergenceIsReportedWithStatusThree) {
  const fs::path out = fresh_dir("cap");
  const Result r = bedforge("pack --aspect-ratio 5 --count 200 --max-iterations 100 -o " + out.string());
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("max_iterations"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "bed.csv"));
}

TEST(CommandLine, HelpStatesTypesUnitsAndDefaults) {
  const Result r = bedforge("pack --help");
  EXPECT_EQ(r.status, 0);
  for (const char* s : {"--aspect-ratio", "particle diameters", "--diameter-m", "metres", "default 0.001",
                        "--seed", "default 1", "--mode", "default accelerated"})
    EXPECT_NE(r.output.find(s), std::string::npos) << s;
}

#ifdef BEDFORGE_HAVE_CGAL
TEST(CommandLine, SurfaceStageOnAPackedBed) {
  const fs::path dir = fresh_dir("surface");
  ASSERT_EQ(bedforge("--quiet pack --aspect-ratio 4 --count 30 -o " + dir.string()).status, 0);
  const Result r = bedforge("surface " + dir.string() + " --contacts shrink --edge-length-d 0.15");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("closed, no self-intersection"), std::string::npos) << r.output;
  for (const char* f : {"fluid.stl", "fluid_inlet.stl", "fluid_outlet.stl", "fluid_wall.stl", "fluid_particles.stl",
                        "bed.stl"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  std::ifstream report(dir / "report.json");
  const auto j = nlohmann::json::parse(report);
  EXPECT_TRUE(j["stages"].contains("pack"));  // the stage is added, the bed's report kept
  EXPECT_EQ(j["stages"]["surface"]["check"]["closed"], true);
  // Bad input: exit 2, message names the key and what is allowed, nothing written.
  const Result bad = bedforge("surface " + dir.string() + " --contacts glue");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("contacts.treatment"), std::string::npos) << bad.output;
  // A clip window replaces the empty sections: the domain runs between its planes, each within
  // clip_shift_d (0.25 d) of where it was asked.
  const Result clip = bedforge("--quiet surface " + dir.string() + " --clip-window-d 1 3 --edge-length-d 0.15");
  ASSERT_EQ(clip.status, 0) << clip.output;
  std::ifstream clipped(dir / "report.json");
  const auto s = nlohmann::json::parse(clipped)["stages"]["surface"];
  EXPECT_EQ(s["check"]["closed"], true);
  // The domain's planes (m) stand in the ratio of the window's used heights (d).
  EXPECT_NEAR(s["domain_m"]["outlet_z"].get<double>() / s["domain_m"]["inlet_z"].get<double>(),
              s["clip"]["outlet"]["used_d"].get<double>() / s["clip"]["inlet"]["used_d"].get<double>(), 1e-9);
  EXPECT_NEAR(s["clip"]["inlet"]["used_d"].get<double>(), 1.0, 0.25);
  EXPECT_NEAR(s["clip"]["outlet"]["used_d"].get<double>(), 3.0, 0.25);
  // Cut through the bridges its planes cross instead of opening them: none opened.
  const Result cut = bedforge("--quiet surface " + dir.string() +
                              " --clip-window-d 1 3 --edge-length-d 0.15 --contacts bridge --at-clip-planes cut");
  ASSERT_EQ(cut.status, 0) << cut.output;
  std::ifstream cut_report(dir / "report.json");
  const auto c = nlohmann::json::parse(cut_report)["stages"]["surface"];
  EXPECT_EQ(c["parameters"]["at_clip_planes"], "cut");
  EXPECT_EQ(c["clip"]["inlet"]["contacts_opened"].get<long>() + c["clip"]["outlet"]["contacts_opened"].get<long>(), 0);
  EXPECT_EQ(bedforge("surface " + dir.string() + " --at-clip-planes slice").status, 2);
  const Result reversed = bedforge("surface " + dir.string() + " --clip-window-d 3 1");
  EXPECT_EQ(reversed.status, 2);
  EXPECT_NE(reversed.output.find("surface.clip_window_d"), std::string::npos) << reversed.output;
}

// `bedforge mesh DIR` meshes DIR/fluid.stl as it is; slabs are surfaces built again from the
// bed, so a scene asking for them there is refused by name before anything is meshed.
TEST(CommandLine, MeshingADirectoryInSlabsIsRefused) {
  const fs::path dir = fresh_dir("mesh_slabs");
  ASSERT_EQ(bedforge("--quiet pack --aspect-ratio 4 --count 30 -o " + dir.string()).status, 0);
  ASSERT_EQ(bedforge("--quiet surface " + dir.string() + " --edge-length-d 0.2").status, 0);
  std::ofstream(dir / "scene.toml", std::ios::app) << "\n[mesh]\nslabs = 3\n";
  const Result r = bedforge("mesh " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.slabs = 3"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "fluid.msh"));
}

TEST(CommandLine, SurfaceBelowTheAngleGateFailsAndWritesItsTriangles) {
  // A clip window cuts spheres near the wall and each other, leaving narrow inlet and outlet
  // triangles (13 degrees on this bed); a gate at 20 degrees refuses them. The stage fails
  // (exit 3) naming the key and the particles, writes no surface, and leaves
  // bad_triangles.vtp holding exactly the triangles below the gate, counted here from the
  // ASCII STL of the same surface built with the default gate.
  const fs::path dir = fresh_dir("surface_gate");
  ASSERT_EQ(bedforge("--quiet pack --aspect-ratio 4 --count 30 -o " + dir.string()).status, 0);
  const std::string surface = "surface " + dir.string() + " --edge-length-d 0.15 --clip-window-d 1 3";
  const Result passed = bedforge("--quiet " + surface);
  ASSERT_EQ(passed.status, 0) << passed.output;
  std::istringstream stl(read(dir / "fluid.stl"));
  std::vector<Eigen::Vector3d> corner;
  long below = 0;
  for (std::string word; stl >> word;) {
    if (word != "vertex") continue;
    Eigen::Vector3d v;
    stl >> v.x() >> v.y() >> v.z();
    corner.push_back(v);
    if (corner.size() < 3) continue;
    double smallest = 180.0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = corner[(k + 1) % 3] - corner[k], w = corner[(k + 2) % 3] - corner[k];
      smallest = std::min(smallest, std::acos(u.dot(w) / (u.norm() * w.norm())) * 180.0 / M_PI);
    }
    below += smallest < 20.0;
    corner.clear();
  }
  ASSERT_GT(below, 0);
  fs::remove(dir / "fluid.stl");
  const Result r = bedforge(surface + " --min-angle-deg 20");
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find(std::to_string(below) + " triangles have an angle below surface.min_angle_deg = 20"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("most near particle"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "fluid.stl"));
  ASSERT_TRUE(fs::exists(dir / "bad_triangles.vtp"));
  EXPECT_NE(read(dir / "bad_triangles.vtp").find("NumberOfPolys=\"" + std::to_string(below) + "\""), std::string::npos);
}
#endif
