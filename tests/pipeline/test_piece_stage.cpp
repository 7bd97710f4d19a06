// A case written in pieces, one per Open MPI rank (`mpirun -np 2 bedforge piece DIR`), runs in
// parallel straight away, with no decomposePar, and gives the bed's pressure drop of the same
// slabs joined into one mesh. On gmsh's tetrahedra the pieces' cells are their slabs', each held
// to the gate; on the polyhedral dual each piece holds whole cells across the plane (its
// neighbour's tetrahedra next to it exchanged through files), so the pieces are the joined dual's
// cells. checkMesh passes across the pieces and on the mesh reconstructed from them.
// (Skipped when OpenFOAM's programs are not on PATH.)
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cases/case_writer.hpp"
#include "core/bed_io.hpp"
#include "meshing/volume/dual_pieces.hpp"
#include "meshing/volume/processor_patches.hpp"
#include "meshing/volume/slab_mesh.hpp"
#include "pipeline/piece_stage.hpp"
#include "pipeline/scene.hpp"
#include "support/cli.hpp"

namespace fs = std::filesystem;
using namespace cli_test;

namespace {

bool have_openfoam() { return shell("command -v simpleFoam && command -v mpirun").status == 0; }

const char* kScene =
    "[container]\ntype = \"cylinder\"\ndiameter_d = 4.0\n[particles]\ncount = 60\ndiameter_m = 0.003\n"
    "[packing]\nseed = 2\n[contacts]\ntreatment = \"shrink\"\n[surface]\nedge_length_d = 0.2\n"
    "[case.convergence]\nlevels = 0\n[outputs]\nfiles = [\"positions\", \"case\"]\n"
    "[case]\nprocessors = 2\n";

// `bedforge run` of kScene, the case solved or only written, on `cells`, with `mesh` the [mesh]
// section (slabs joined by default), a convergence study of `levels` and the contacts
// `treatment`, into a fresh directory `name`.
fs::path run(const std::string& name, bool solve, const std::string& cells = "polyhedra",
             const std::string& mesh = "[mesh]\nslabs = 2\n", int levels = 0, const std::string& treatment = "shrink") {
  const fs::path dir = fresh_dir(name), scene = fresh_dir(name + "_scene");
  fs::create_directories(scene);
  std::string text = kScene;
  text.replace(text.find("levels = 0"), 10, "levels = " + std::to_string(levels));
  text.replace(text.find("\"shrink\""), 8, "\"" + treatment + "\"");
  std::ofstream(scene / "s.toml") << text << (solve ? "run = true\n" : "run = false\n") << "cells = \"" << cells
                                  << "\"\n" << mesh;
  const Result r = cli_test::bedforge("--quiet run " + (scene / "s.toml").string() + " -o " + dir.string());
  EXPECT_EQ(r.status, 0) << r.output;
  return dir;
}

double said_gradient(const std::string& log) {
  const auto at = log.find("dp/L over the bed section");
  if (at == std::string::npos) return NAN;
  return std::stod(log.substr(log.find("m): ", at) + 4));
}

const std::string kOpenFoam =
    "export WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam}; "
    "[ \"$(id -u)\" = 0 ] && export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; ";

// The pieces of dir/case gathered into one mesh (reconstructParMesh), then checkMesh on it.
Result gather(const fs::path& dir) {
  return shell(kOpenFoam + "cd " + (dir / "case").string() + " && rm -rf constant/polyMesh && reconstructParMesh "
               "-constant > log.reconstructParMesh 2>&1 && checkMesh");
}

// The pieces of dir/case gathered into one mesh pass checkMesh with `cells`.
void expect_gathered(const fs::path& dir, long cells) {
  const Result gathered = gather(dir);
  ASSERT_EQ(gathered.status, 0) << read(dir / "case/log.reconstructParMesh");
  EXPECT_NE(gathered.output.find("Mesh OK."), std::string::npos) << gathered.output;
  EXPECT_NE(gathered.output.find(fmt::format("cells:            {}", cells)), std::string::npos) << gathered.output;
}

}  // namespace

// Also a study in pieces: its coarser levels are made by ranks too, each level's case in pieces in
// its own directory beside the bed and scene its ranks read, each level's cells the size the
// study asked for (ratio 1.3 between levels, to the study's sizing tolerance of 3 % where its
// four attempts reached it), and the run ends in the study's grid convergence index.
TEST(PieceStage, ARunInTwoPiecesGivesThePressureDropOfTheJoinedSlabsAndItsStudyInPieces) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam, mpirun) not on PATH";
  // The same slabs joined into one mesh, solved on two processes through decomposePar.
  const fs::path joined = run("piece_joined", true);
  const auto report = nlohmann::json::parse(read(joined / "report.json"));
  const double joined_gradient = report["stages"]["case"]["flow"]["pressure_gradient_bed_pa_m"].get<double>();
  const long joined_cells = report["stages"]["case"]["cells"].get<long>();

  // mesh.pieces = 2: the run writes the case, two ranks its pieces, and Allrun solves them.
  const fs::path dir = run("piece_pieces", true, "polyhedra", "[mesh]\npieces = 2\n", 3);
  const auto pieces_report = nlohmann::json::parse(read(dir / "report.json"));
  const auto& c = pieces_report["stages"]["case"];
  EXPECT_FALSE(pieces_report["stages"].contains("mesh")) << "no whole mesh is made";
  long cells = 0, plane_faces = 0;
  for (int k = 0; k < 2; ++k) {
    const auto r = nlohmann::json::parse(read(dir / fmt::format("case/processor{}/bedforge_piece.json", k)));
    EXPECT_EQ(r["piece"].get<int>(), k);
    cells += r["cells"].get<long>();
    EXPECT_TRUE(fs::exists(dir / fmt::format("case/processor{}/0/U", k)));
  }
  EXPECT_EQ(c["cells"].get<long>(), cells);
  // Each piece names its neighbour across the plane, with as many faces on either side.
  for (int k = 0; k < 2; ++k) {
    const std::string boundary = read(dir / fmt::format("case/processor{}/constant/polyMesh/boundary", k));
    const auto at = boundary.find(fmt::format("procBoundary{}to{}", k, 1 - k));
    ASSERT_NE(at, std::string::npos) << boundary;
    const auto n = boundary.find("nFaces", at);
    const long faces = std::stol(boundary.substr(boundary.find_first_of("0123456789", n)));
    if (k == 0) plane_faces = faces;
    EXPECT_EQ(faces, plane_faces);
    // Its files record the bed's seed (the scene's 2) and which piece it is.
    EXPECT_NE(boundary.find(fmt::format("seed 2, piece {} of 2", k)), std::string::npos) << boundary;
  }
  // One dual cell per point of the slabs' tetrahedra, as joined (gmsh's threads make a few
  // hundred more or fewer tetrahedra on each run: 0.3 % of the cells allowed).
  EXPECT_NEAR(cells, joined_cells, joined_cells * 3 / 1000);
  EXPECT_FALSE(fs::exists(dir / "case/piece_layers")) << "the ranks' exchange is removed";

  // Solved on the pieces as they are: parallel checkMesh and simpleFoam, no decomposePar.
  EXPECT_FALSE(fs::exists(dir / "case/log.decomposePar"));
  const std::string check = read(dir / "case/log.checkMesh");
  EXPECT_NE(check.find(fmt::format("cells:            {}", cells)), std::string::npos) << check;
  EXPECT_NE(check.find("Mesh OK."), std::string::npos) << check;
  EXPECT_TRUE(c["flow"]["converged"].get<bool>()) << c["flow"].dump();
  EXPECT_EQ(c["flow"]["mesh"]["cells"].get<long>(), cells);
  // Issue 58's rule for the pieces against the one-piece route at the same settings: dp/L within
  // 0.5 % (the cells differ only at the planes between pieces).
  const double gradient = c["flow"]["pressure_gradient_bed_pa_m"].get<double>();
  EXPECT_NEAR(gradient, joined_gradient, 0.005 * joined_gradient);
  EXPECT_NE(said_gradient(read(dir / "case/log.Allrun")), 0.0);
  EXPECT_NEAR(said_gradient(read(dir / "case/log.Allrun")), gradient, 1e-5 * gradient);
  // The whole mesh can be gathered from the pieces: reconstructParMesh, then checkMesh on it.
  expect_gathered(dir, cells);

  // The study's levels in pieces.
  const auto& study = c["convergence"];
  ASSERT_TRUE(study["complete"].get<bool>()) << study.dump();
  EXPECT_TRUE(std::isfinite(study["grid_convergence"]["gci_fine"].get<double>())) << study.dump();
  EXPECT_TRUE(c.contains("answer"));
  const auto& levels = study["levels"];
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(levels[0]["cells"].get<long>(), cells);
  for (int k = 1; k < 3; ++k) {
    const fs::path level = dir / fmt::format("convergence/level_{}", k + 1);
    for (const char* piece : {"case/processor0", "case/processor1"})
      EXPECT_TRUE(fs::exists(level / piece / "constant/polyMesh/owner")) << level / piece;
    EXPECT_TRUE(fs::exists(level / "bed.csv"));
    EXPECT_FALSE(fs::exists(level / "case/constant/polyMesh/owner")) << "no whole mesh of the level";
    EXPECT_LT(levels[k]["cells"].get<long>(), levels[k - 1]["cells"].get<long>());
    EXPECT_TRUE(levels[k]["converged"].get<bool>());
    const double h = levels[k]["cell_size_m"].get<double>(), wanted = levels[0]["cell_size_m"].get<double>() * std::pow(1.3, k);
    if (levels[k]["sizing"].size() < 4) {
      EXPECT_NEAR(h / wanted, 1.0, 0.03) << "level " << k + 1;
    }
  }
}

// Bridged contacts in pieces: each rank cuts its slab, bridges and all, from its own widened
// window (meshing/volume/slab_mesh.hpp); the ranks' planes match (the case runs in parallel and
// gathers into one mesh of the pieces' cells), and the pressure drop is the joined slabs' (the
// same windows, meshed one after the other in one process) within issue 58's 0.5 %: gmsh's
// threads make other tetrahedra on each run. Not asserted: checkMesh's "Mesh OK". This bed's
// pieces passed it once the plane's face took cells across its narrow gaps (2026-11-30, session
// 49; 1 polyhedron failed before), but the default bed's pieces still fail 5-6 beside their
// planes (docs/findings.md): issue 58's checkMesh target is not met for cut planes; the run
// says so in its checkMesh line, and that is checked here.
TEST(PieceStage, BridgedPiecesGiveThePressureDropOfTheJoinedSlabs) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (simpleFoam, mpirun) not on PATH";
  const fs::path joined = run("piece_bridged_joined", true, "polyhedra", "[mesh]\nslabs = 2\n", 0, "bridge");
  const double joined_gradient = nlohmann::json::parse(read(joined / "report.json"))["stages"]["case"]["flow"]
                                     ["pressure_gradient_bed_pa_m"].get<double>();
  const fs::path dir = run("piece_bridged", true, "polyhedra", "[mesh]\npieces = 2\n", 0, "bridge");
  const auto report = nlohmann::json::parse(read(dir / "report.json"));
  const auto& c = report["stages"]["case"];
  long cells = 0, failing = 0;
  for (int k = 0; k < 2; ++k) {
    const auto piece = nlohmann::json::parse(read(dir / fmt::format("case/processor{}/bedforge_piece.json", k)));
    ASSERT_EQ(piece["slab"]["plane_cut"].size(), 1u) << piece["slab"].dump();
    EXPECT_GT(piece["slab"]["plane_cut"][0]["loops"].get<long>(), 1) << "the plane cuts spheres and bridges";
    cells += piece["cells"].get<long>();
    failing += piece["polyhedra_quality"]["failing_cells"].get<long>();
  }
  EXPECT_EQ(c["cells"].get<long>(), cells);
  const std::string check = read(dir / "case/log.checkMesh");
  EXPECT_NE(check.find(fmt::format("cells:            {}", cells)), std::string::npos) << check;
  EXPECT_EQ(check.find("Mesh OK.") != std::string::npos, failing == 0) << "the pieces' own check agrees with checkMesh";
  EXPECT_TRUE(c["flow"]["converged"].get<bool>()) << c["flow"].dump();
  const double gradient = c["flow"]["pressure_gradient_bed_pa_m"].get<double>();
  EXPECT_NEAR(gradient, joined_gradient, 0.005 * joined_gradient);
  const Result gathered = gather(dir);
  EXPECT_NE(gathered.output.find(fmt::format("cells:            {}", cells)), std::string::npos) << gathered.output;
}

TEST(PieceStage, OnTetrahedraThePiecesPassCheckMeshAndGatherIntoOneMesh) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  const fs::path dir = run("piece_tetrahedra", false, "tetrahedra");
  const Result pieces = shell(kOpenFoam + "mpirun -np 2 " + BEDFORGE_BINARY + " --quiet piece " + dir.string());
  ASSERT_EQ(pieces.status, 0) << pieces.output;
  long cells = 0;
  for (int k = 0; k < 2; ++k)
    cells += nlohmann::json::parse(read(dir / fmt::format("case/processor{}/bedforge_piece.json", k)))["cells"].get<long>();
  // Each piece's tetrahedra are its slab's, held to the mesh stage's gate as the joined slabs
  // are (gmsh's threads make other ones on each run, so not the joined run's own).
  const Result check = shell(kOpenFoam + "cd " + (dir / "case").string() + " && mpirun -np 2 checkMesh -parallel");
  ASSERT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find("Mesh OK."), std::string::npos) << check.output;
  EXPECT_NE(check.output.find(fmt::format("cells:            {}", cells)), std::string::npos) << check.output;
  // The whole mesh can still be gathered: reconstructParMesh, then checkMesh on it.
  expect_gathered(dir, cells);
}

// A rerun after a failed piece meshes only that piece again: the others keep their tetrahedra
// (kept beside the case until the run's pieces are all done) and, on polyhedra, make their dual
// again with the new piece's cells next to them, so the pieces still match (checkMesh).
TEST(PieceStage, ARerunMeshesOnlyTheFailedPiece) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  const fs::path dir = run("piece_rerun", false, "polyhedra", "[mesh]\npieces = 2\n");
  EXPECT_FALSE(fs::exists(dir / "case/piece_layers")) << "a run that succeeded leaves no pieces' files";
  // The ranks on their own, as a scheduler's job would run them: their files stay.
  const std::string ranks = kOpenFoam + "mpirun -np 2 " + BEDFORGE_BINARY + " piece " + dir.string();
  Result r = shell(ranks);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("kept from an earlier run"), std::string::npos) << "no tetrahedra were kept yet: " << r.output;
  // Piece 1 fails (as if its rank had been killed): its directory and its tetrahedra are gone.
  fs::remove_all(dir / "case/processor1");
  fs::remove(dir / "case/piece_layers/piece1_tetrahedra.bin");
  // The run again, every stage redone: the bed and the settings are the same, so piece 0 keeps
  // its tetrahedra and only piece 1 is meshed.
  const fs::path scene = fs::path(fresh_dir("piece_rerun_scene").string() + "_again.toml");
  std::ofstream(scene) << read(dir / "scene.toml");
  r = cli_test::bedforge("--quiet run " + scene.string() + " -o " + dir.string() + " --overwrite --force");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto piece0 = nlohmann::json::parse(read(dir / "case/processor0/bedforge_piece.json"));
  const auto piece1 = nlohmann::json::parse(read(dir / "case/processor1/bedforge_piece.json"));
  EXPECT_TRUE(piece0["slab"].value("reused", false)) << piece0.dump();
  EXPECT_FALSE(piece1["slab"].value("reused", false)) << piece1.dump();
  EXPECT_TRUE(piece1["slab"].contains("cells")) << "meshed again: " << piece1.dump();
  EXPECT_FALSE(fs::exists(dir / "case/piece_layers"));
  const Result check = shell(kOpenFoam + "cd " + (dir / "case").string() + " && mpirun -np 2 checkMesh -parallel");
  ASSERT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find("Mesh OK."), std::string::npos) << check.output;
}

// Each rank compares its planes' two sides as OpenFOAM will, before OpenFOAM reads them: a piece
// whose processor faces do not match its neighbour's stops the run, naming both pieces and the
// face, with the faces in a table beside the case, and so does a piece without a patch towards
// its neighbour; so do the ranks started by hand (`mpirun bedforge piece`), and a piece made
// alone beside a neighbour already written. (The mismatch is made in what piece 2 recorded of its
// plane, two faces swapped, then none; each rerun keeps both pieces' tetrahedra, so only the
// comparison sees them again.)
TEST(PieceStage, PiecesWhosePlaneFacesDoNotMatchStopTheRunNamingThePlane) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  const fs::path dir = run("piece_mismatch", false, "tetrahedra", "[mesh]\npieces = 2\n");
  const fs::path recorded = dir / "case/processor1" / bedforge::cases::kProcessorFacesFile;
  std::vector<bedforge::meshing::ProcessorFaces> upper = bedforge::meshing::read_processor_faces(recorded);
  ASSERT_EQ(upper.size(), 1u);
  ASSERT_GT(upper[0].centres.size(), 20u);
  std::swap(upper[0].centres[4], upper[0].centres[9]);
  bedforge::meshing::write_processor_faces(recorded, upper);
  const fs::path scene = fs::path(fresh_dir("piece_mismatch_scene").string() + "_again.toml");
  std::ofstream(scene) << read(dir / "scene.toml");
  const Result r = cli_test::bedforge("--quiet run " + scene.string() + " -o " + dir.string() + " --overwrite --force");
  EXPECT_NE(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("pieces 1 and 2 do not match at the plane between them"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("2 of procBoundary0to1's"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("first: face 4 at"), std::string::npos) << r.output;
  const fs::path table = dir / "case/mismatched_faces_procBoundary0to1.csv";
  ASSERT_TRUE(fs::exists(table)) << r.output;
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(std::ifstream(table).rdbuf()), {}, '\n'), 3);
  // The ranks by hand at the run's planes, then the lower piece alone (no job around it).
  fs::remove(table);
  const Result by_hand =
      shell(kOpenFoam + "mpirun -np 2 " + BEDFORGE_BINARY + " --quiet --no-progress piece " + dir.string());
  EXPECT_NE(by_hand.status, 0) << by_hand.output;
  EXPECT_NE(by_hand.output.find("pieces 1 and 2 do not match at the plane between them"), std::string::npos)
      << by_hand.output;
  EXPECT_TRUE(fs::exists(table)) << by_hand.output;
  const Result alone = cli_test::bedforge("--quiet piece " + dir.string() + " --piece 0 --pieces 2");
  EXPECT_NE(alone.status, 0) << alone.output;
  EXPECT_NE(alone.output.find("first: face 4 at"), std::string::npos) << alone.output;
  // A piece that recorded no patch towards its neighbour: named from the neighbour's side.
  bedforge::meshing::write_processor_faces(recorded, {});
  const Result again =
      cli_test::bedforge("--quiet run " + scene.string() + " -o " + dir.string() + " --overwrite --force");
  EXPECT_NE(again.status, 0) << again.output;
  EXPECT_NE(again.output.find("processor1 has no patch procBoundary1to0"), std::string::npos) << again.output;
}

// When a piece fails, only its planes move (meshing::moved_slab_planes_d, as the run's retry
// moves them): a piece whose planes stayed keeps the tetrahedra it made, and the pieces, kept and
// new, still form one case whose processor patches match (checkMesh -parallel reads it whole, and
// a rank refuses a neighbour's cells that do not meet its own at their plane). A bed 19 d tall in
// 3 pieces of 6 d: the top piece's window does not reach the lowest plane.
TEST(PieceStage, APieceWhosePlanesStayKeepsItsCellsWhenAnotherPlaneMoves) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  std::string tall = kScene;
  tall.replace(tall.find("diameter_d = 4.0"), 16, "diameter_d = 3.0");
  tall.replace(tall.find("count = 60"), 10, "count = 150");
  tall.replace(tall.find("edge_length_d = 0.2"), 19, "edge_length_d = 0.2\ncells_per_gap = 0");
  const fs::path dir = fresh_dir("piece_kept"), scene = fresh_dir("piece_kept_scene");
  fs::create_directories(scene);
  std::ofstream(scene / "s.toml") << tall << "run = false\n[mesh]\npieces = 3\n";
  const std::string oversubscribed = kOpenFoam + "export OMPI_MCA_rmaps_base_oversubscribe=1; ";
  Result r = shell(oversubscribed + BEDFORGE_BINARY + " --quiet run " + (scene / "s.toml").string() + " -o " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  // The ranks on their own at the run's planes, so that their tetrahedra stay on disk; then
  // again as if piece 1 of 3 had failed: the lowest plane moves, the other stays.
  const bedforge::pipeline::Scene s = bedforge::pipeline::read_scene_file(dir / "scene.toml");
  const bedforge::Bed bed = bedforge::read_bed_text(dir / "bed.csv", 1.0).bed;
  const std::vector<double> planes = bedforge::meshing::slab_planes_d(bed, s.surface, 3),
                            moved = bedforge::meshing::moved_slab_planes_d(bed, s.surface, planes, {0});
  ASSERT_NE(moved[0], planes[0]);
  ASSERT_EQ(moved[1], planes[1]);
  const auto ranks = [&](const std::vector<double>& at) {
    return shell(oversubscribed + "mpirun -np 3 " + BEDFORGE_BINARY + " --quiet --no-progress piece " + dir.string() +
                 fmt::format(" --planes-d {:.17g} {:.17g}", at[0], at[1]));
  };
  r = ranks(planes);
  ASSERT_EQ(r.status, 0) << r.output;
  r = ranks(moved);
  ASSERT_EQ(r.status, 0) << r.output;
  long cells = 0;
  for (int k = 0; k < 3; ++k) {
    const auto p = nlohmann::json::parse(read(dir / fmt::format("case/processor{}/bedforge_piece.json", k)));
    EXPECT_EQ(p["slab"].value("reused", false), k == 2) << "piece " << k << ": " << p.dump();
    cells += p["cells"].get<long>();
  }
  const Result check =
      shell(oversubscribed + "cd " + (dir / "case").string() + " && mpirun -np 3 checkMesh -parallel");
  ASSERT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find(fmt::format("cells:            {}", cells)), std::string::npos) << check.output;
}

// More ranks than mpirun has slots (cores, or a batch job's tasks): the run says so, naming
// mesh.pieces and how to run more ranks than cores, not as an internal error.
TEST(PieceStage, MoreRanksThanMpirunHasSlotsAreRefusedNamingThePieces) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  const fs::path dir = fresh_dir("piece_slots"), scene = fresh_dir("piece_slots_scene");
  fs::create_directories(scene);
  std::ofstream(scene / "s.toml") << kScene << "run = false\n[mesh]\npieces = 4096\n";
  const Result r = shell(kOpenFoam + "env -u OMPI_MCA_rmaps_base_oversubscribe " + BEDFORGE_BINARY + " --quiet run " +
                         (scene / "s.toml").string() + " -o " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.pieces = 4096: mpirun has fewer slots than 4096 ranks here"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("OMPI_MCA_rmaps_base_oversubscribe=1"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "case/processor0"));
}

// mpirun's own words and exit code when a rank stops: the run reads the signal when one was
// killed from outside (as the kernel kills a process for want of memory), the rank's own
// error, and which rank stopped first where mpirun names it (it did in 4 of 6 runs here: its
// notice races with its abort), from this machine's Open MPI, here of ranks that stop on purpose.
TEST(PieceStage, TheRankThatStoppedAndTheSignalThatKilledItAreReadFromMpirun) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (mpirun) not on PATH";
  const fs::path dir = fresh_dir("piece_ranks_log");
  fs::create_directories(dir);
  const auto job = [&](const std::string& name, const std::string& rank_one) {
    const fs::path log = dir / name;
    const Result r = shell(kOpenFoam + "mpirun -np 2 sh -c 'if [ $OMPI_COMM_WORLD_RANK = 1 ]; then " + rank_one +
                           "; fi; sleep 2' > " + log.string() + " 2>&1; echo $?");
    return std::pair{bedforge::pipeline::read_ranks_log(log, std::stoi(r.output)), read(log)};
  };
  const auto [killed, killed_log] = job("killed.log", "kill -9 $$");
  EXPECT_EQ(killed.signal, 9) << killed_log;
  EXPECT_EQ(killed.signal_name, "Killed") << killed_log;
  EXPECT_EQ(killed.message, "") << killed_log;
  EXPECT_TRUE(killed.failed_rank == 1 || killed.failed_rank == -1) << killed_log;
  const auto [failed, failed_log] = job("failed.log", "echo \"bedforge: error: the reason\"; exit 2");
  EXPECT_EQ(failed.signal, 0) << failed_log;
  EXPECT_EQ(failed.message, "bedforge: error: the reason") << failed_log;
  EXPECT_TRUE(failed.failed_rank == 1 || failed.failed_rank == -1) << failed_log;
  EXPECT_FALSE(failed.too_few_slots) << failed_log;
}

// A piece failing the gate where the whole mesh would pass has its planes to blame: the ranks
// mesh again with the planes moved, and when that fails too the run stops (exit 3) naming both
// attempts. Here a gate no tetrahedral mesh of a bed passes (10 deg), so both fail (one
// algorithm and one optimiser pass each, to fail fast).
TEST(PieceStage, APieceFailingTheGateIsMeshedAgainWithThePlanesMovedAndTheErrorNamesBoth) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (checkMesh, mpirun) not on PATH";
  const fs::path dir = fresh_dir("piece_gate"), scene = fresh_dir("piece_gate_scene");
  fs::create_directories(scene);
  std::string text = kScene;
  text.replace(text.find("edge_length_d = 0.2"), 19, "edge_length_d = 0.35");
  std::ofstream(scene / "s.toml") << text << "run = false\n[mesh]\npieces = 2\nfallback = false\nmax_optimize_passes = 1\n"
                                  << "[mesh.gate]\nmax_non_orthogonality_deg = 10\n";
  const Result r = cli_test::bedforge("run " + (scene / "s.toml").string() + " -o " + dir.string());
  EXPECT_EQ(r.status, 3) << r.output;
  const auto moved = r.output.find("and with the planes moved from ");
  ASSERT_NE(moved, std::string::npos) << r.output;
  // Each attempt's failure is a rank's, naming its piece's slab and the gate.
  EXPECT_LT(r.output.find("of 2 ("), moved) << r.output;
  EXPECT_GT(r.output.rfind("of 2 ("), moved) << r.output;
  EXPECT_NE(r.output.find("meshing again with the planes moved"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "case/processor0/constant/polyMesh/owner"));
}

// A piece that cannot be cut from the bed (its clip planes may move 0.05 d, and need a gap of
// 0.2 d between the spheres' ends for the clearance asked, where this bed has some 30 per d)
// has its planes to blame too: the ranks try again with the planes moved, and the run stops
// (exit 2) naming mesh.pieces and both attempts; no processor directory holds cells.
TEST(PieceStage, APieceThatCannotBeCutIsTriedAgainWithThePlanesMovedAndTheErrorNamesBoth) {
  if (!have_openfoam()) GTEST_SKIP() << "OpenFOAM (mpirun) not on PATH";
  const fs::path dir = fresh_dir("piece_cut"), scene = fresh_dir("piece_cut_scene");
  fs::create_directories(scene);
  std::string text = kScene;
  text.replace(text.find("edge_length_d = 0.2"), 19, "edge_length_d = 0.2\nclip_shift_d = 0.05\nclip_clearance_d = 0.1");
  std::ofstream(scene / "s.toml") << text << "run = false\n[mesh]\npieces = 2\n";
  const Result r = cli_test::bedforge("run " + (scene / "s.toml").string() + " -o " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bedforge: error: mesh.pieces: the case's pieces: "), std::string::npos) << r.output;
  const auto moved = r.output.find("; and with the planes moved from ");
  ASSERT_NE(moved, std::string::npos) << r.output;
  EXPECT_LT(r.output.find("cannot be cut from the bed"), moved) << r.output;
  EXPECT_GT(r.output.rfind("cannot be cut from the bed"), moved) << r.output;
  EXPECT_NE(r.output.find("meshing again with the planes moved"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "case/log.pieces_planes_moved"));
  EXPECT_FALSE(fs::exists(dir / "case/processor0/constant/polyMesh/owner"));
  EXPECT_FALSE(fs::exists(dir / "case/processor1/constant/polyMesh/owner"));
}

// Refused before any meshing, with exit status 2 and what is allowed: a piece outside the count,
// a wall gap not above 0, no case to write into, pieces beyond the machine's memory, planes that
// do not fit the pieces, a piece on polyhedra made without its neighbours or with a neighbour's
// cells made for other planes, and contacts a plane would cut open; no processor directory is left.
TEST(PieceStage, BadRequestsAreRefusedBeforeAnyWork) {
  const fs::path dir = fresh_dir("piece_refused");
  ASSERT_EQ(cli_test::bedforge("--quiet pack --aspect-ratio 3 --count 12 --diameter-m 0.002 -o " + dir.string()).status, 0);
  Result r = cli_test::bedforge("piece " + dir.string() + " --piece 2 --pieces 2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--piece 2: allowed: 0 to 1"), std::string::npos) << r.output;
  r = cli_test::bedforge("piece " + dir.string() + " --piece 0 --pieces 2 --wall-gap-m -1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--wall-gap-m: -1; allowed: a number > 0 (m)"), std::string::npos) << r.output;
  r = shell("env -u OMPI_COMM_WORLD_RANK " + std::string(BEDFORGE_BINARY) + " piece " + dir.string() + " --pieces 2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--piece not given and OMPI_COMM_WORLD_RANK not set"), std::string::npos) << r.output;
  r = cli_test::bedforge("piece " + dir.string() + " --piece 0 --pieces 2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no case to write a piece into"), std::string::npos) << r.output;
  fs::create_directories(dir / "case/0");
  // More ranks on this machine than its memory holds pieces for (a million, each with half of
  // this bed's estimated cells): refused before meshing, with the count that would fit.
  r = shell("OMPI_COMM_WORLD_LOCAL_SIZE=1000000 " + std::string(BEDFORGE_BINARY) + " piece " + dir.string() +
            " --piece 0 --pieces 2 --contacts shrink");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.pieces = 2: piece 1 would take about"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("allowed: mesh.pieces >= "), std::string::npos) << r.output;
  // Its cells mostly across the shrunk contacts' gaps: the gaps' settings are named too. Without
  // refined gaps the estimate is the bound that errs low.
  EXPECT_NE(r.output.find("fewer surface.cells_per_gap, now 4, or a longer surface.contact_edge_length_d"),
            std::string::npos) << r.output;
  r = shell("OMPI_COMM_WORLD_LOCAL_SIZE=1000000 " + std::string(BEDFORGE_BINARY) + " piece " + dir.string() +
            " --piece 0 --pieces 2 --contacts shrink --cells-per-gap 0");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("piece 1 would take at least"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("cells_per_gap"), std::string::npos) << r.output;
  // Planes given for the pieces: one fewer than the pieces, increasing, inside the domain.
  r = cli_test::bedforge("piece " + dir.string() + " --piece 0 --pieces 2 --contacts shrink --planes-d 0.5 1.0");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--planes-d 0.5 1: allowed: 1 height (d above the floor)"), std::string::npos) << r.output;
  // A piece on polyhedra made alone (outside an Open MPI job), with no neighbour's layer to take,
  // or with one an earlier run left for another bed, other settings or other planes.
  const auto alone = [&](const std::string& said) {
    const Result a = shell("env -u OMPI_COMM_WORLD_SIZE " + std::string(BEDFORGE_BINARY) + " piece " + dir.string() +
                           " --piece 0 --pieces 2 --contacts shrink");
    EXPECT_EQ(a.status, 2) << a.output;
    EXPECT_NE(a.output.find(said), std::string::npos) << a.output;
  };
  alone("piece 1's cells next to piece 0 are not there; allowed: the pieces of a case on polyhedra made together");
  bedforge::meshing::PlaneLayer stale;
  stale.tag = "1234 another run's plane";
  fs::create_directories(dir / "case/piece_layers");
  bedforge::meshing::write_plane_layer(dir / "case/piece_layers/piece1_inlet.bin", stale);
  alone("piece 1's cells next to piece 0 were made for another bed, other settings or another plane than ");
  fs::remove_all(dir / "case/piece_layers");
  r = cli_test::bedforge("piece " + dir.string() + " --piece 0 --pieces 2 --layers 2");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.layers.count = 2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("allowed for pieces: mesh.layers.count = 0"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "case/processor0"));
  // A scene asking for pieces the route cannot make is refused when read, naming mesh.pieces:
  // the default scene with prism layers.
  std::string scene = read(fs::path(BEDFORGE_SOURCE_DIR) / "scenes/default.toml");
  scene.replace(scene.find("algorithm = \"hxt\""), 17, "algorithm = \"hxt\"\npieces = 2\nlayers.count = 2");
  const fs::path out = fresh_dir("piece_refused_run"), file = fresh_dir("piece_refused_scene");
  fs::create_directories(file);
  std::ofstream(file / "s.toml") << scene;
  r = cli_test::bedforge("run " + (file / "s.toml").string() + " -o " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.pieces = 2"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("mesh.layers.count = 2"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "bed.csv"));
}
