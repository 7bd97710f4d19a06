// The OpenFOAM case as a user gets it from bedforge, checked by OpenFOAM itself (Debian's
// `openfoam`; these tests are skipped when its programs are not on PATH).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "support/cli.hpp"

namespace fs = std::filesystem;
using namespace cli_test;

namespace {

bool have_openfoam() { return shell("command -v checkMesh").status == 0; }

Result check_mesh(const fs::path& case_dir) {
  return shell("cd " + case_dir.string() + " && WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam} checkMesh");
}

// A bed of 12 spheres in a = 3: a cheap mesh that has every patch.
fs::path meshed_bed(const std::string& name) {
  const fs::path dir = fresh_dir(name);
  EXPECT_EQ(bedforge("--quiet pack --aspect-ratio 3 --count 12 --diameter-m 0.002 -o " + dir.string()).status, 0);
  EXPECT_EQ(bedforge("--quiet surface " + dir.string() + " --edge-length-d 0.1").status, 0);
  const Result r = bedforge("--quiet mesh " + dir.string());
  EXPECT_EQ(r.status, 0) << r.output;
  return dir;
}

// `bedforge run` on a scene given as TOML text, into a fresh directory `name`; returns it.
fs::path run_scene_text(const std::string& name, const std::string& toml, Result& result) {
  const fs::path dir = fresh_dir(name), scene = fresh_dir(name + "_scene");
  fs::create_directories(scene);
  std::ofstream(scene / "s.toml") << toml;
  result = bedforge("--quiet run " + (scene / "s.toml").string() + " -o " + dir.string());
  return dir;
}

}  // namespace

// The shipped default scene with its text changed: each `{from, to}` must occur in it once.
std::string default_scene_with(const std::vector<std::pair<std::string, std::string>>& changes) {
  std::string text = read(fs::path(BEDFORGE_SOURCE_DIR) / "scenes/default.toml");
  for (const auto& [from, to] : changes) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "scenes/default.toml has no '" << from << "'";
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "scenes/default.toml has '" << from << "' twice";
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  return text;
}

// The README's path, the default scene, on a small bed (a = 4, N = 40 instead of a = 5, N = 500;
// every other setting as shipped): bed, surface, mesh, case and three solves end in the answer,
// its band and the correlation, on the terminal, in summary.txt, report.json and the picture.
// Then the bed solved once more on a mesh one ratio finer than the study's finest: a value the
// study did not see, which its band must hold (the band is meant to hold the mesh-independent
// value, which that finer mesh is nearer to, with about 95 % confidence).
TEST(OpenFoamCase, TheDefaultScenesPathEndsInThePressureDropWithItsBand) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  const fs::path out = fresh_dir("default");
  const std::string small = " --aspect-ratio 4 --count 40";
  const Result r = bedforge("run scenes/default.toml" + small + " -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("analysis: eps whole"), std::string::npos) << r.output;
  for (const char* f : {"case/Allrun", "case/Allclean", "case/constant/polyMesh/faces", "case/0/U", "case/0/p",
                        "case/system/decomposeParDict", "case/bedforge/scene.toml", "case/bedforge/bed.csv",
                        "pressure_drop.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const Result c = check_mesh(out / "case");
  EXPECT_NE(c.output.find("Mesh OK."), std::string::npos) << c.output;
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  const auto& stages = report["stages"];
  // The coarser meshes the band rests on pass checkMesh too. On the polyhedra the default scene
  // had until 2026-12-04, levels 2 and 3 failed 5 and 63 cells here before the bridges to the wall
  // took a shorter edge, and a sliver gmsh leaves on the wall on some runs failed 5 cells of level 2
  // in CI until the case cut such ears off (docs/findings.md, 2026-11-29, sessions 45 and 46).
  const auto& levels = stages["case"]["convergence"]["levels"];
  ASSERT_EQ(levels.size(), 3u) << stages["case"]["convergence"].dump(1);
  for (const auto& level : levels) {
    EXPECT_EQ(level.at("cells_failing_check_mesh").get<long>(), 0) << stages["case"]["convergence"].dump(1);
    const int k = level.at("level").get<int>();
    if (k == 1) continue;  // the case itself, checked above
    const Result ck = check_mesh(out / "convergence" / ("level_" + std::to_string(k)));
    EXPECT_NE(ck.output.find("Mesh OK."), std::string::npos) << "level " << k << "\n" << ck.output;
  }
  // The answer is the run's last word, and summary.txt's.
  const auto& answer = stages["case"]["answer"];
  ASSERT_TRUE(answer.contains("best_estimate_pa_m")) << answer.dump(1);
  const std::string printed_answer = r.output.substr(r.output.rfind("answer: dp/L over the bed section"));
  for (const auto& line : answer["lines"]) {
    EXPECT_NE(printed_answer.find(line.get<std::string>()), std::string::npos) << line;
    EXPECT_NE(read(out / "summary.txt").find(line.get<std::string>()), std::string::npos) << line;
  }
  for (const char* what : {"best estimate: ", "band: ", "iteration error, ", "Eisfeld & Schnitzlein (2001): ", "picture: "})
    EXPECT_NE(printed_answer.find(what), std::string::npos) << what << " in\n" << printed_answer;
  const double low = answer["band_pa_m"][0].get<double>(), high = answer["band_pa_m"][1].get<double>();
  const double best = answer["best_estimate_pa_m"].get<double>();
  EXPECT_LT(low, best);
  EXPECT_LT(best, high);
  EXPECT_EQ(answer["reference"]["pa_m"], stages["case"]["flow"]["eisfeld_schnitzlein_bed_pa_m"]);
  // The mesh encloses what the surface enclosed: the same volume error against the exact volume.
  EXPECT_NEAR(stages["mesh"]["fluid_volume_relative_error"].get<double>(),
              stages["surface"]["fluid_volume_relative_error"].get<double>(), 1e-9);
  // Every stage reports its time and its own peak memory, in the report and in its summary line.
  for (const char* stage : {"pack", "analysis", "surface", "mesh", "case"}) {
    EXPECT_GT(stages[stage]["peak_memory_mb"].get<double>(), 0.0) << stage;
    EXPECT_GE(stages[stage]["time_s"].get<double>(), 0.0) << stage;
    EXPECT_NE(stages[stage]["summary"].get<std::string>().find(" MB"), std::string::npos) << stage;
  }
  // The optimiser's history: quality after generation, then after each pass, ending at the
  // quality the stage reports.
  const auto& attempt = stages["mesh"]["attempts"].back();
  const auto& history = attempt["history"];
  ASSERT_GE(history.size(), 1u) << attempt.dump();
  EXPECT_EQ(history[0]["pass"], 0);
  for (std::size_t k = 1; k < history.size(); ++k)
    EXPECT_GT(history[k]["time_s"].get<double>(), history[k - 1]["time_s"].get<double>());
  EXPECT_EQ(history.back()["max_non_orthogonality_deg"], stages["mesh"]["quality"]["max_non_orthogonality_deg"]);

  // One ratio (1.3) finer: every mesh length over 1.3, cells per gap times 1.3, one mesh.
  const fs::path finer_scene = fresh_dir("default_finer_scene") / "finer.toml";
  fs::create_directories(finer_scene.parent_path());
  std::ofstream(finer_scene) << default_scene_with({{"edge_length_d = 0.195", "edge_length_d = 0.15"},
                                                    {"contact_edge_length_d = 0.065", "contact_edge_length_d = 0.05"},
                                                    {"cells_per_gap = 3.0769", "cells_per_gap = 4"},
                                                    {"max_size_d = 0.325", "max_size_d = 0.25"},
                                                    {"levels = 3", "levels = 0"}});
  const fs::path finer = fresh_dir("default_finer");
  const Result f = bedforge("--quiet run " + finer_scene.string() + small + " -o " + finer.string());
  ASSERT_EQ(f.status, 0) << f.output;
  const auto finer_flow = nlohmann::json::parse(read(finer / "report.json"))["stages"]["case"]["flow"];
  const double finer_value = finer_flow["pressure_gradient_bed_pa_m"].get<double>();
  EXPECT_GT(finer_flow["mesh"]["cells"].get<long>(), stages["case"]["flow"]["mesh"]["cells"].get<long>());
  EXPECT_GE(finer_value, low) << answer.dump(1);
  EXPECT_LE(finer_value, high) << answer.dump(1);
}

// Changing only the case settings reuses the mesh (and the surface and bed under it), changing
// nothing reuses the case as well, and changing the mesh settings meshes again from a surface
// built again.
TEST(OpenFoamCase, ChangingOnlyTheCaseReusesTheMesh) {
  const std::string base =
      "[container]\ndiameter_d = 3\n[particles]\ncount = 12\ndiameter_m = 0.002\n[surface]\nedge_length_d = 0.15\n"
      "[outputs]\nfiles = [\"positions\", \"stl\", \"mesh\", \"case\"]\n";
  const fs::path dir = fresh_dir("reuse_mesh"), scenes = fresh_dir("reuse_mesh_scenes");
  fs::create_directories(scenes);
  auto run = [&](const std::string& name, const std::string& extra) {
    std::ofstream(scenes / name) << base << extra;
    return bedforge("run " + (scenes / name).string() + " -o " + dir.string() + " --overwrite");
  };
  const Result first = run("a.toml", "[case]\nreynolds = 1.0\n");
  ASSERT_EQ(first.status, 0) << first.output;
  const auto msh_time = fs::last_write_time(dir / "fluid.msh");
  const auto first_report = nlohmann::json::parse(read(dir / "report.json"));
  const auto cells = first_report["stages"]["mesh"]["cells"];
  const auto case_cells = first_report["stages"]["case"]["cells"];  // the dual's, one per point of the mesh

  const Result case_only = run("b.toml", "[case]\nreynolds = 2.0\n");
  ASSERT_EQ(case_only.status, 0) << case_only.output;
  EXPECT_NE(case_only.output.find("mesh: reused"), std::string::npos) << case_only.output;
  EXPECT_NE(case_only.output.find("surface: reused"), std::string::npos) << case_only.output;
  EXPECT_EQ(fs::last_write_time(dir / "fluid.msh"), msh_time);
  auto report = nlohmann::json::parse(read(dir / "report.json"));
  EXPECT_TRUE(report["stages"]["mesh"].value("reused", false));
  EXPECT_EQ(report["stages"]["mesh"]["cells"], cells);
  EXPECT_EQ(report["stages"]["case"]["parameters"]["reynolds"], 2.0);  // the case itself was written again
  EXPECT_NE(read(dir / "case/constant/polyMesh/owner").find("nCells:" + case_cells.dump()), std::string::npos);

  // Nothing changed: the case is reused too, so no --overwrite is needed.
  const auto u_time = fs::last_write_time(dir / "case/0/U");
  const Result same = bedforge("run " + (scenes / "b.toml").string() + " -o " + dir.string());
  ASSERT_EQ(same.status, 0) << same.output;
  EXPECT_NE(same.output.find("case: reused"), std::string::npos) << same.output;
  EXPECT_EQ(fs::last_write_time(dir / "case/0/U"), u_time);

  const Result new_mesh = run("c.toml", "[case]\nreynolds = 2.0\n[mesh]\nmax_size_d = 0.2\n");
  ASSERT_EQ(new_mesh.status, 0) << new_mesh.output;
  EXPECT_EQ(new_mesh.output.find("mesh: reused"), std::string::npos) << new_mesh.output;
  EXPECT_EQ(new_mesh.output.find("surface: reused"), std::string::npos) << new_mesh.output;
  EXPECT_NE(new_mesh.output.find("pack: reused"), std::string::npos) << new_mesh.output;
  report = nlohmann::json::parse(read(dir / "report.json"));
  EXPECT_FALSE(report["stages"]["mesh"].value("reused", false));
  EXPECT_EQ(report["stages"]["mesh"]["parameters"]["max_size_d"], 0.2);
}

TEST(OpenFoamCase, BinaryAndAsciiCasesAreTheSameMeshToCheckMesh) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh) not on PATH";
  const fs::path dir = meshed_bed("formats");
  ASSERT_EQ(bedforge("--quiet case " + dir.string() + " --format ascii").status, 0);
  const Result ascii = check_mesh(dir / "case");
  ASSERT_NE(ascii.output.find("Mesh OK."), std::string::npos) << ascii.output;
  ASSERT_EQ(bedforge("--quiet case " + dir.string() + " --overwrite").status, 0);
  const Result binary = check_mesh(dir / "case");
  ASSERT_NE(binary.output.find("Mesh OK."), std::string::npos) << binary.output;
  // checkMesh's statistics (cells, faces, volumes, quality) agree line for line after the header.
  auto stats = [](const std::string& s) { return s.substr(s.find("Mesh stats"), s.find("End") - s.find("Mesh stats")); };
  EXPECT_EQ(stats(ascii.output), stats(binary.output));
  EXPECT_NE(binary.output.find("polyhedra:"), std::string::npos) << binary.output;  // the dual, by default
  // The mesh stage's own quality figures are checkMesh's on its tetrahedra, computed the same way.
  ASSERT_EQ(bedforge("--quiet case " + dir.string() + " --cells tetrahedra --overwrite").status, 0);
  const Result tetrahedra = check_mesh(dir / "case");
  ASSERT_NE(tetrahedra.output.find("Mesh OK."), std::string::npos) << tetrahedra.output;
  auto number_after = [&](const std::string& key) {
    const auto at = tetrahedra.output.find(key);
    return at == std::string::npos ? -1.0 : std::stod(tetrahedra.output.substr(at + key.size()));
  };
  const auto q = nlohmann::json::parse(read(dir / "report.json"))["stages"]["mesh"]["quality"];
  EXPECT_NEAR(q["max_non_orthogonality_deg"].get<double>(), number_after("Mesh non-orthogonality Max:"), 1e-6);
  EXPECT_NEAR(q["mean_non_orthogonality_deg"].get<double>(), number_after("average:"), 1e-6);
  EXPECT_NEAR(q["max_skewness"].get<double>(), number_after("Max skewness ="), 1e-6);
  EXPECT_NEAR(q["max_aspect_ratio"].get<double>(), number_after("Max aspect ratio ="), 1e-6);
  // checkMesh names the faces over 70 degrees only when there are some.
  const double over_70 = number_after("(> 70 degrees) faces:");
  EXPECT_EQ(q["faces_over_70_deg"].get<long>(), over_70 < 0.0 ? 0L : static_cast<long>(over_70));
}

TEST(OpenFoamCase, AnExistingCaseIsNotOverwrittenUnlessAsked) {
  const fs::path dir = meshed_bed("exists");
  ASSERT_EQ(bedforge("--quiet case " + dir.string()).status, 0);
  const auto before = fs::last_write_time(dir / "case/0/U");
  const Result again = bedforge("case " + dir.string());
  EXPECT_EQ(again.status, 2) << again.output;
  EXPECT_NE(again.output.find("--overwrite"), std::string::npos) << again.output;
  EXPECT_EQ(fs::last_write_time(dir / "case/0/U"), before);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos) << e.path();
}

TEST(OpenFoamCase, ACaseWithoutAMeshAndAMeshWithoutAClosedSurfaceAreRefused) {
  const fs::path dir = fresh_dir("no_mesh");
  ASSERT_EQ(bedforge("--quiet pack --aspect-ratio 3 --count 12 -o " + dir.string()).status, 0);
  const Result no_mesh = bedforge("case " + dir.string());
  EXPECT_EQ(no_mesh.status, 2) << no_mesh.output;
  EXPECT_NE(no_mesh.output.find("fluid.msh"), std::string::npos) << no_mesh.output;
  EXPECT_FALSE(fs::exists(dir / "case"));
  // snappyHexMesh's cells need no gmsh mesh but the surface they are made from.
  const Result no_surface = bedforge("case " + dir.string() + " --mesher snappy");
  EXPECT_EQ(no_surface.status, 2) << no_surface.output;
  EXPECT_NE(no_surface.output.find("fluid.stl"), std::string::npos) << no_surface.output;
  EXPECT_FALSE(fs::exists(dir / "case"));
  // An STL with one facet cut out: the mesh stage names the file and where it is open.
  ASSERT_EQ(bedforge("--quiet surface " + dir.string() + "").status, 0);
  std::string stl = read(dir / "fluid.stl");
  const auto facet = stl.find("  facet normal");
  stl.erase(facet, stl.find("endfacet", facet) + 9 - facet);
  std::ofstream(dir / "fluid.stl") << stl;
  const Result open = bedforge("mesh " + dir.string());
  EXPECT_EQ(open.status, 2) << open.output;
  EXPECT_NE(open.output.find("not closed"), std::string::npos) << open.output;
  EXPECT_FALSE(fs::exists(dir / "fluid.msh"));
}

// Prism layers on the particles: checkMesh passes the mixed mesh (prisms, pyramids,
// tetrahedra) and its dual, and the mixed mesh's quality figures are the mesh stage's own.
TEST(OpenFoamCase, PrismLayersGiveACaseCheckMeshPasses) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh) not on PATH";
  const fs::path dir = fresh_dir("layers");
  ASSERT_EQ(bedforge("--quiet pack --aspect-ratio 3 --count 12 --diameter-m 0.002 -o " + dir.string()).status, 0);
  ASSERT_EQ(bedforge("--quiet surface " + dir.string() + " --edge-length-d 0.1").status, 0);
  const Result m = bedforge("mesh " + dir.string() + " --layers 3 --layer-thickness-d 0.02");
  ASSERT_EQ(m.status, 0) << m.output;
  EXPECT_NE(m.output.find("3 prism layers"), std::string::npos) << m.output;
  // Their dual, the default cells, passes too.
  ASSERT_EQ(bedforge("--quiet case " + dir.string()).status, 0);
  const Result dual = check_mesh(dir / "case");
  ASSERT_NE(dual.output.find("Mesh OK."), std::string::npos) << dual.output;
  ASSERT_EQ(bedforge("--quiet case " + dir.string() + " --cells tetrahedra --overwrite").status, 0);
  const Result c = check_mesh(dir / "case");
  ASSERT_NE(c.output.find("Mesh OK."), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("prisms:"), std::string::npos) << c.output;
  auto number_after = [&](const std::string& key) {
    const auto at = c.output.find(key);
    return at == std::string::npos ? -1.0 : std::stod(c.output.substr(at + key.size()));
  };
  EXPECT_GT(number_after("prisms:"), 0.0) << c.output;
  const auto q = nlohmann::json::parse(read(dir / "report.json"))["stages"]["mesh"]["quality"];
  EXPECT_NEAR(q["max_non_orthogonality_deg"].get<double>(), number_after("Mesh non-orthogonality Max:"), 1e-6);
  EXPECT_NEAR(q["max_skewness"].get<double>(), number_after("Max skewness ="), 1e-6);
  EXPECT_NEAR(q["max_aspect_ratio"].get<double>(), number_after("Max aspect ratio ="), 1e-6);
}

// A walled box: checkMesh passes, and the correlation sees the box through its cross-section
// (3 d x 4 d: area 12 d^2, hydraulic diameter 4 A / P = 24/7 d).
TEST(OpenFoamCase, AWalledBoxGivesACaseCheckMeshPasses) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh) not on PATH";
  const fs::path dir = fresh_dir("box");
  const double d = 0.002;
  fs::create_directories(dir);
  std::ofstream(dir / "box.toml") << "[container]\ntype = \"box\"\nsize_x_d = 3\nsize_y_d = 4\n";
  ASSERT_EQ(bedforge("--quiet pack --scene " + (dir / "box.toml").string() + " --count 12 --diameter-m " + std::to_string(d) + " -o " +
                     dir.string())
                .status,
            0);
  ASSERT_EQ(bedforge("--quiet surface " + dir.string() + " --edge-length-d 0.1").status, 0);
  ASSERT_EQ(bedforge("--quiet mesh " + dir.string()).status, 0);
  const Result r = bedforge("--quiet case " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const Result c = check_mesh(dir / "case");
  EXPECT_NE(c.output.find("Mesh OK."), std::string::npos) << c.output;
  const auto cs = nlohmann::json::parse(read(dir / "report.json"))["stages"]["case"];
  EXPECT_NEAR(cs["inlet_area_m2"].get<double>(), 12.0 * d * d, 1e-12);
  EXPECT_NEAR(cs["aspect_ratio"].get<double>(), 24.0 / 7.0, 1e-9);
  // The section's meshed void fraction against the exact one of the packed spheres: shrinking
  // by 0.99 and the inscribed facets (every vertex on the sphere, so each facetted sphere holds
  // the ball of its radius less the chordal deviation) only take solid away, at most down to
  // 0.99^3 (1 - deviation / r)^3 of it. Cells are counted by their centre, an error of about a
  // cell's height over the section's (0.1 d / 2 d), hence the margin of 0.01 either way.
  const double eps_bed = cs["section"]["void_fraction_bed"].get<double>();
  const double eps_mesh = cs["section"]["void_fraction_mesh"].get<double>();
  const double deviation = nlohmann::json::parse(read(dir / "report.json"))["stages"]["surface"]["chordal_deviation_d"];
  const double kept = std::pow(0.99, 3) * std::pow(1.0 - deviation / 0.495, 3);
  EXPECT_GT(eps_mesh, eps_bed - 0.01);
  EXPECT_LT(eps_mesh, 1.0 - (1.0 - eps_bed) * kept + 0.01) << eps_bed << " " << kept;
}

// A clip window of a bridged bed, its planes given no room (clip_shift_d 0.02) and cut through
// the contacts they cross (contacts.at_clip_planes = "cut"): solved, its inlet (the fluid's part
// of a plane through the bed) carries the superficial velocity times the whole section, not the
// velocity over the fluid's part (which once gave 0.6 of the flow rate and 0.31 x Eisfeld &
// Schnitzlein on the default bed's window); nothing is opened; and dp/L lies where the small
// bed's one-mesh dp/L lies (the band of SmallBedPressureDropAgreesWithEisfeldSchnitzlein below).
// The same window in 2 pieces on ranks of their own (whose windows ring and cut their walls at
// the window's planes and at theirs, and read the bed from bed.csv though the scene asks only for
// the case): checkMesh -parallel passes (with the window's rings alone the pieces' shared faces
// missed each other by 1.5 % of their area), and dp/L near the one piece's: on this window of
// 48 k cells three runs read +0.3, +0.4 and +0.7 % (the planes' cells, and HXT's threads make
// each mesh anew), so within 2 %.
TEST(OpenFoamCase, AClipWindowCutThroughItsBridgesCarriesTheFlowRateSet) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  const std::string scene =
      "[container]\ndiameter_d = 4.0\n[particles]\ncount = 60\ndiameter_m = 0.003\n[packing]\nseed = 1\n"
      "[contacts]\ntreatment = \"bridge\"\nat_clip_planes = \"cut\"\n"
      "[surface]\nedge_length_d = 0.15\ncontact_edge_length_d = 0.05\ncells_per_gap = 0\nclip_window_d = [1.0, 3.0]\n"
      "clip_shift_d = 0.02\n"
      "[case]\ncells = \"tetrahedra\"\nprocessors = 2\nrun = true\nconvergence = {levels = 0}\n"
      "[outputs]\nfiles = [\"case\"]\n";
  Result r;
  const fs::path out = run_scene_text("clip_cut", scene, r);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  const auto& clip = report["stages"]["surface"]["clip"];
  for (const char* plane : {"inlet", "outlet"}) {
    EXPECT_EQ(clip[plane]["contacts_opened"].get<long>(), 0) << clip.dump();
    EXPECT_GT(clip[plane]["cut"]["loops"].get<long>(), 1) << plane << ": the plane cuts spheres, not only the wall";
  }
  EXPECT_NE(read(out / "case/0/U").find("flowRateInletVelocity"), std::string::npos);
  const auto& flow = report["stages"]["case"]["flow"];
  EXPECT_LT(std::abs(flow["flow_rate_relative_error"].get<double>()), 1e-3) << flow.dump();
  const double ratio = flow["ratio_to_eisfeld_schnitzlein_bed"].get<double>();
  EXPECT_GT(ratio, 0.8 * 0.65) << flow.dump();
  EXPECT_LT(ratio, 1.2) << flow.dump();
  Result rp;
  const fs::path pieces = run_scene_text("clip_cut_pieces", scene + "[mesh]\npieces = 2\n", rp);
  ASSERT_EQ(rp.status, 0) << rp.output;
  EXPECT_NE(read(pieces / "case/log.checkMesh").find("Mesh OK."), std::string::npos);
  const auto pieces_report = nlohmann::json::parse(read(pieces / "report.json"));
  const auto& in_pieces = pieces_report["stages"]["case"]["flow"];
  EXPECT_NEAR(in_pieces["pressure_gradient_bed_pa_m"].get<double>(), flow["pressure_gradient_bed_pa_m"].get<double>(),
              0.02 * flow["pressure_gradient_bed_pa_m"].get<double>());
}

// case.drag_by_gap_d splits the particles' and walls' patches and nothing else: on the same gmsh
// cells (the mesh reused) dp/L and the particles' and walls' drag are those without it, to
// rounding; the bands sum to the particles' drag; and the walls' drag in the section (theirs less
// that beyond its planes) and the section's bands' form and viscous drag sum to dp/L times the
// section's fluid volume, the momentum balance between its planes. Measured with walls that slip
// (no wall drag): +1.0 % at this 0.2 d (two meshes) and +0.74 % at 0.15 d; with walls that do
// not slip, as here: +0.75 and +0.81 % (two meshes; 2026-12-06; the faces cut by the planes go
// whole to one side by their centres), so 2 %. The walls whole, their ends kept, gave +7.3 and
// +7.4 %; a band left out or the mean pressure's share kept would miss by tens of %.
TEST(OpenFoamCase, TheDragByGapSumsToTheSectionsMomentumBalanceOnTheSameCells) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  const std::string base =
      "[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\n[particles]\ncount = 40\ndiameter_m = 0.003\n"
      "[surface]\nedge_length_d = 0.2\ncontact_edge_length_d = 0.1\n[mesh]\nalgorithm = \"hxt\"\n"
      "[outputs]\nfiles = [\"positions\", \"mesh\", \"case\"]\n"
      "[case]\ncells = \"tetrahedra\"\nprocessors = 2\nrun = true\n";
  const fs::path dir = fresh_dir("drag_by_gap"), scenes = fresh_dir("drag_by_gap_scenes");
  fs::create_directories(scenes);
  auto run = [&](const std::string& name, const std::string& extra) {
    std::ofstream(scenes / name) << base << extra << "[case.convergence]\nlevels = 0\n";
    const Result r = bedforge("--quiet run " + (scenes / name).string() + " -o " + dir.string() + " --overwrite");
    EXPECT_EQ(r.status, 0) << r.output;
    return nlohmann::json::parse(read(dir / "report.json"))["stages"]["case"];
  };
  const auto whole = run("whole.toml", "");
  const auto split = run("split.toml", "drag_by_gap_d = [0.03, 0.3]\n");
  EXPECT_TRUE(split.contains("flow"));
  const auto& flow = split["flow"];
  EXPECT_EQ(split["cells"], whole["cells"]);
  const double dp = flow["pressure_gradient_bed_pa_m"].get<double>();
  EXPECT_NEAR(dp, whole["flow"]["pressure_gradient_bed_pa_m"].get<double>(), 1e-9 * dp);
  const double particles = flow["drag"]["particles_n"].get<double>();
  EXPECT_NEAR(particles, whole["flow"]["drag"]["particles_n"].get<double>(), 1e-9 * particles);
  const auto& bands = flow["drag"]["particles_by_gap"];
  ASSERT_EQ(bands.size(), 4u);  // three by gap, the ends
  double sum = 0.0, section = 0.0;
  for (const auto& b : bands) {
    sum += b["drag_n"].get<double>();
    if (b["in_section"].get<bool>()) section += b["form_n"].get<double>() + b["viscous_n"].get<double>();
  }
  EXPECT_NEAR(sum, particles, 1e-6 * particles);
  const double walls = flow["drag"]["walls_n"].get<double>(), ends = flow["drag"]["walls_ends_n"].get<double>();
  EXPECT_NEAR(walls, whole["flow"]["drag"]["walls_n"].get<double>(), 1e-9 * walls);
  EXPECT_GT(ends, 0.0);  // the walls beside the inlet's and outlet's lengths
  EXPECT_LT(ends, walls);
  section += walls - ends;
  const auto& s = split["section"];
  const double fluid = s["void_fraction_mesh"].get<double>() * split["inlet_area_m2"].get<double>() *
                       (s["z_high_m"].get<double>() - s["z_low_m"].get<double>());
  EXPECT_NEAR(section / (dp * fluid), 1.0, 0.02) << flow["drag"].dump(1);
}

TEST(OpenFoamCase, SmallBedPressureDropAgreesWithEisfeldSchnitzlein) {
  // scenes/examples/small_bed_flow.toml: a = 4, N = 40, 0.1 d mesh, Re_p = 1, on two cores.
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  const fs::path out = fresh_dir("flow");
  const Result r = bedforge("run scenes/examples/small_bed_flow.toml -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  const auto& c = report["stages"]["case"];
  const auto& flow = c["flow"];
  // Converged: SIMPLE met its residual targets, and the pressure gradient stopped moving.
  EXPECT_TRUE(flow["converged"].get<bool>()) << flow.dump();
  EXPECT_LE(flow["final_initial_residual"]["p"].get<double>(), c["parameters"]["residual_p"].get<double>());
  EXPECT_LE(flow["final_initial_residual"]["U"].get<double>(), c["parameters"]["residual_u"].get<double>());
  EXPECT_LT(flow["pressure_gradient_change_last_block"].get<double>(), 1e-3);
  // The solve's history ends at the final residuals, its time never runs backwards, and the
  // residuals fell from where they started.
  const auto& history = flow["history"];
  ASSERT_GE(history.size(), 2u);
  EXPECT_EQ(history.back()["iteration"], flow["iterations"]);
  EXPECT_EQ(history.back()["residual_p"], flow["final_initial_residual"]["p"]);
  for (std::size_t k = 1; k < history.size(); ++k)
    EXPECT_GE(history[k]["time_s"].get<double>(), history[k - 1]["time_s"].get<double>());
  EXPECT_LT(history.back()["residual_p"].get<double>(), history[0]["residual_p"].get<double>());
  EXPECT_GT(flow["solver_peak_memory_mb"].get<double>(), 0.0);
  // Mass conservation: what leaves is what the inlet velocity brings.
  EXPECT_LT(std::abs(flow["flow_rate_relative_error"].get<double>()), 1e-3);
  // Momentum: the drag on walls and particles is the push through inlet and outlet. Measured
  // (2026-11-26) +0.36 % here and -1.5 to -2.1 % in the empty tube's coarse meshes (the forces
  // object's wall gradient; -0.32 % of it the momentum flux from plug to parabola), so 2 %; a
  // patch left out (the particles carry about 90 %), a sign or a density would miss by far more.
  const auto& drag = flow["drag"];
  EXPECT_GT(drag["walls_n"].get<double>(), 0.0) << drag.dump();
  EXPECT_GT(drag["particles_n"].get<double>(), 0.0) << drag.dump();
  EXPECT_LT(std::abs(drag["force_balance_relative_error"].get<double>()), 0.02) << drag.dump();
  // Solved on the polyhedral dual (the default), the cells written, not on gmsh's tetrahedra.
  EXPECT_EQ(flow["mesh"]["mesher"], "gmsh polyhedral dual");
  EXPECT_EQ(flow["mesh"]["cells"].get<long>(), c["cells"].get<long>());
  EXPECT_LT(flow["mesh"]["cells"].get<long>(), report["stages"]["mesh"]["cells"].get<long>());
  // Eisfeld & Schnitzlein at the section's exact void fraction: the correlation's own scatter
  // is +-20 % (correlations.md, grade C), and this 0.1 d mesh is not converged: on this bed the
  // dual's dp/L at 0.1 d was 0.65 of what its 0.1, 0.07, 0.05 d sequence extrapolates to
  // (13.7 against about 21 Pa/m, issue 24). Hence 0.8 x 0.65 below and 1.2 above. (The
  // tetrahedra's 0.8-1.2 at the meshed void fraction held only through their +16 % bias.)
  const double ratio = flow["ratio_to_eisfeld_schnitzlein_bed"].get<double>();
  EXPECT_GT(ratio, 0.8 * 0.65) << flow.dump();
  EXPECT_LT(ratio, 1.2) << flow.dump();
  // Allrun ends by saying the result, the same number bedforge read back, to its 6 digits.
  const std::string allrun_log = read(out / "case/log.Allrun");
  const auto at = allrun_log.find("dp/L over the bed section");
  ASSERT_NE(at, std::string::npos) << allrun_log;
  const double said = std::stod(allrun_log.substr(allrun_log.find("m): ", at) + 4));
  EXPECT_NEAR(said, flow["pressure_gradient_bed_pa_m"].get<double>(), 1e-5 * said) << allrun_log;
  EXPECT_NE(allrun_log.find("postProcessing/pBedBottom/0/surfaceFieldValue.dat", at), std::string::npos);
  // One mesh: the answer gives the value and says its error is unknown, and how to learn it.
  const auto& answer = c["answer"];
  EXPECT_FALSE(answer.contains("best_estimate_pa_m")) << answer.dump(1);
  EXPECT_NE(answer["advice"].get<std::string>().find("levels = 3"), std::string::npos) << answer.dump(1);
  EXPECT_NE(r.output.find("no error band, so no best estimate"), std::string::npos) << r.output;
}

// Without OpenFOAM (PATH holds none of its programs) a scene that asks for the flow says so
// before any work, writes its case all the same and exits with status 4, printing no pressure
// drop; once OpenFOAM is there, the same command solves the case it wrote.
TEST(OpenFoamCase, WithoutOpenFoamTheCaseIsWrittenNotSolvedAndTheRunSaysSo) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  const fs::path scene = fresh_dir("no_openfoam_scene") / "s.toml", out = fresh_dir("no_openfoam");
  fs::create_directories(scene.parent_path());
  std::ofstream(scene) << "[container]\ndiameter_d = 3\n[particles]\ncount = 12\ndiameter_m = 0.002\n"
                          "[contacts]\ntreatment = \"shrink\"\n[surface]\nedge_length_d = 0.15\ncells_per_gap = 0\n"
                          "[case]\nrun = true\n[case.convergence]\nlevels = 0\n[outputs]\nfiles = [\"case\"]\n";
  const std::string run = "run " + scene.string() + " -o " + out.string();
  const Result r = shell("PATH=/nonexistent " + std::string(BEDFORGE_BINARY) + " " + run);
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_NE(r.output.find("simpleFoam is not on PATH: the case will be written but not solved"), std::string::npos)
      << r.output;
  EXPECT_LT(r.output.find("is not on PATH"), r.output.find("pack:")) << r.output;  // said first
  EXPECT_EQ(r.output.find("answer:"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(out / "case/Allrun"));
  EXPECT_TRUE(fs::exists(out / "case/constant/polyMesh/owner"));
  EXPECT_FALSE(fs::exists(out / "pressure_drop.svg"));
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  EXPECT_FALSE(report["stages"]["case"].contains("flow"));
  const Result solved = bedforge(run + " --overwrite");
  ASSERT_EQ(solved.status, 0) << solved.output;
  EXPECT_NE(solved.output.find("answer: dp/L over the bed section"), std::string::npos) << solved.output;
  EXPECT_TRUE(nlohmann::json::parse(read(out / "report.json"))["stages"]["case"].contains("flow"));
}

// Prism layers on the small bed: U's residual stalls near 3e-3 on them while the pressure drop
// has settled (docs/findings.md, 2026-11-26, night), so with residual_u unset the case stops on
// 1e-2 for U: SIMPLE converges well inside 300 iterations (at 1e-4 it ran to the cap), and dp/L
// moved by under 1e-3 of itself over its last block of them.
TEST(OpenFoamCase, OnPrismLayersTheSolverStopsOnceThePressureDropHasSettled) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam) not on PATH";
  Result r;
  const fs::path out = run_scene_text("layers_flow",
                                      "[container]\ntype = \"cylinder\"\ndiameter_d = 4.0\n"
                                      "[particles]\ncount = 40\ndiameter_m = 0.003\n[packing]\nseed = 1\n"
                                      "[contacts]\ntreatment = \"shrink\"\n"
                                      "[surface]\nedge_length_d = 0.1\ncontact_edge_length_d = 0.033\n"
                                      "cells_per_gap = 0\n[mesh.layers]\ncount = 3\n"
                                      "[case]\niterations = 300\nprocessors = 2\nrun = true\n"
                                      "[case.convergence]\nlevels = 0\n"
                                      "[outputs]\nfiles = [\"case\"]\n",
                                      r);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto report = nlohmann::json::parse(read(out / "report.json"));
  const auto& c = report["stages"]["case"];
  const auto& flow = c["flow"];
  EXPECT_EQ(c["parameters"]["residual_u"].get<double>(), 1e-2);
  EXPECT_TRUE(flow["converged"].get<bool>()) << flow["final_initial_residual"].dump();
  EXPECT_LT(flow["iterations"].get<int>(), 300);
  EXPECT_LT(flow["pressure_gradient_change_last_block"].get<double>(), 1e-3);
}

// snappyHexMesh's cells (case.mesher = "snappy"), the route past one machine: the run makes no
// gmsh mesh, and the case's Allrun -np 2 meshes under MPI and solves on the decomposed cells as
// they are, cut to a few solver iterations. The mesh passes checkMesh and keeps the patch names
// the 0/ files use; the report counts its cells and times Allrun's steps.
TEST(OpenFoamCase, SnappyHexMeshCellsNeedNoGmshMeshAndPassCheckMesh) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (snappyHexMesh) not on PATH";
  Result r;
  const fs::path dir = run_scene_text(
      "snappy",
      "[container]\ndiameter_d = 3\n[particles]\ncount = 12\ndiameter_m = 0.002\n[surface]\nedge_length_d = 0.1\n"
      "[case]\nmesher = \"snappy\"\nsnappy_level = 1\nrun = true\nprocessors = 2\niterations = 5\n"
      "[outputs]\nfiles = [\"positions\", \"case\"]\n",
      r);
  ASSERT_EQ(r.status, 0) << r.output << read(dir / "case/log.Allrun");
  const auto report = nlohmann::json::parse(read(dir / "report.json"));
  EXPECT_FALSE(report["stages"].contains("mesh")) << report["stages"].dump();
  EXPECT_FALSE(fs::exists(dir / "fluid.msh"));
  EXPECT_TRUE(fs::exists(dir / "case/constant/triSurface/fluid.stl"));
  const std::string check = read(dir / "case/log.checkMesh");
  EXPECT_NE(check.find("Mesh OK."), std::string::npos) << check;
  // The STL's named solids became the patches the 0/ files and function objects refer to.
  const std::string boundary = read(dir / "case/processor0/constant/polyMesh/boundary");
  for (const char* patch : {"inlet", "wall", "particles"})
    EXPECT_NE(boundary.find(std::string("    ") + patch + "\n"), std::string::npos) << patch << "\n" << boundary;
  const auto flow = report["stages"]["case"]["flow"];
  const auto at = check.find("cells:");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(flow["mesh"]["mesher"], "snappyHexMesh");
  EXPECT_EQ(flow["mesh"]["cells"].get<long>(), std::atol(check.c_str() + at + 6));
  EXPECT_EQ(flow["iterations"].get<long>(), 5);
  EXPECT_TRUE(flow["void_fraction_section"].is_null()) << flow.dump();  // no cells of ours to measure it on
  // Allrun's steps as GNU time saw them (setup.sh installs it), the meshing among them.
  std::vector<std::string> steps;
  for (const auto& step : flow["allrun_steps"]) steps.push_back(step["step"]);
  EXPECT_EQ(steps, (std::vector<std::string>{"blockMesh", "surfaceFeatureExtract", "decomposePar", "snappyHexMesh",
                                             "checkMesh", "simpleFoam"}));
  // The fluid the cells fill: checkMesh's total volume against the volume the surface encloses
  // (the surface stage's own figure, from the same triangles written at 12 digits).
  const auto vol = check.find("Total volume = ");
  ASSERT_NE(vol, std::string::npos);
  EXPECT_DOUBLE_EQ(flow["mesh"]["volume_m3"].get<double>(), std::atof(check.c_str() + vol + 15));
  const double surface = report["stages"]["case"]["surface_volume_m3"].get<double>();
  EXPECT_NEAR(surface, report["stages"]["surface"]["fluid_volume_mesh_m3"].get<double>(), 1e-9 * surface);
  EXPECT_NEAR(flow["mesh"]["volume_lost"].get<double>(), 1.0 - flow["mesh"]["volume_m3"].get<double>() / surface, 1e-12);
}

// Background cells too coarse for the bed's throats (case.snappy_cell_d = 1: cells of 0.5 d at
// the surfaces, against throats of a few tenths of d between touching spheres): snappyHexMesh
// keeps only the fluid connected to the point inside it, here not the inlet, and the solver
// cannot start. The run stops with the convergence status and names the settings to change.
TEST(OpenFoamCase, SnappyHexMeshCellsThatLoseTheInletNameTheSettingsToChange) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (snappyHexMesh) not on PATH";
  Result r;
  run_scene_text("snappy_coarse",
                 "[container]\ndiameter_d = 4\n[particles]\ncount = 40\ndiameter_m = 0.003\n[surface]\n"
                 "edge_length_d = 0.3\n[case]\nmesher = \"snappy\"\nsnappy_cell_d = 1.0\nsnappy_level = 1\nrun = true\n"
                 "processors = 1\niterations = 5\n[outputs]\nfiles = [\"positions\", \"case\"]\n",
                 r);
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("no inlet faces"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("case.snappy_cell_d = 1,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("case.snappy_level = 1)"), std::string::npos) << r.output;
}

