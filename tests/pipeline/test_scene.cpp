#include "pipeline/scene.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using namespace bedforge::pipeline;

namespace {

Scene read(const std::string& text, const std::filesystem::path& base = {}) {
  return read_scene(parse_scene_text(text, "t.toml"), "t.toml", base);
}

// What reading `text` says: the InputError's message, or "accepted".
std::string message(const std::string& text, const std::filesystem::path& base = {}) {
  try {
    read(text, base);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(Scene, DefaultsAndRequiredKeys) {
  const Scene s = read("[container]\ndiameter_d = 5\n[particles]\ncount = 10\n");
  EXPECT_EQ(s.algorithm, "soft-sphere");
  EXPECT_EQ(s.seed, 1u);
  EXPECT_TRUE(s.wants("positions") && s.wants("vtp") && s.wants("analysis"));
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*s.container).radius(), 0.0025, 1e-15);  // 5 d of 1 mm
  EXPECT_THROW(read("[container]\ndiameter_d = 5\n"), InputError);       // no count
  EXPECT_THROW(read("[particles]\ncount = 10\n"), InputError);           // no container size
}

// particles.count = 0 is the empty container (a run whose flow has an exact answer): there is
// nothing to analyse, so asking for the analysis is refused by name; the case is allowed.
TEST(Scene, AnEmptyContainerRefusesTheAnalysisAndKeepsItsUnit) {
  try {
    read("[container]\ndiameter_d = 2\n[particles]\ncount = 0\n");  // the default outputs include "analysis"
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"analysis\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("particles.count = 0"), std::string::npos) << e.what();
  }
  const Scene s = read("[container]\ndiameter_d = 2\n[particles]\ncount = 0\ndiameter_m = 0.003\n"
                       "[outputs]\nfiles = [\"positions\"]\n");
  EXPECT_EQ(s.count, 0);
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*s.container).radius(), 0.003, 1e-15);
  EXPECT_THROW(read("[container]\ndiameter_d = 2\n[particles]\ncount = -1\n"), InputError);
}

TEST(Scene, AspectRatioIsInSauterMeanDiameters) {
  // d32 of equal numbers of 1 and 2 mm spheres is 1.8 mm.
  const Scene s = read("[container]\ndiameter_d = 10\n[particles]\ncount = 10\ndistribution = \"discrete\"\n"
                       "diameters_m = [0.001, 0.002]\nnumber_fractions = [0.5, 0.5]\n");
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*s.container).radius(), 0.009, 1e-15);
}

TEST(Scene, OverrideReplacesTheLengthInTheOtherUnit) {
  toml::table t = parse_scene_text("[container]\ndiameter_m = 0.02\n[particles]\ncount = 10\n", "t");
  override_key(t, "container.diameter_d", 4.0);
  override_key(t, "packing.soft_sphere.mode", std::string("faithful"));
  const Scene s = read_scene(t, "t");
  EXPECT_NEAR(dynamic_cast<const Cylinder&>(*s.container).radius(), 0.002, 1e-15);
  EXPECT_EQ(s.soft_sphere.mode, packer::SoftSphereParams::Mode::faithful);
  EXPECT_FALSE(t["container"].as_table()->contains("diameter_m"));
}

TEST(Scene, ImportPathIsRelativeToTheSceneFile) {
  try {
    read("[container]\ndiameter_d = 5\n[packing]\nalgorithm = \"import\"\nfile = \"bed.txt\"\n", "/nowhere/scenes");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nowhere/scenes/bed.txt"), std::string::npos) << e.what();
  }
}

// A DEM bed periodic along z (LAMMPS `ff ff pp`) imported into a scene's own container keeps the
// file's period: it was packed so, and without it the bed gained a floor and a top (found
// 2026-12-04: an imported periodic section solved as a bed with ends, 0.56 x Eisfeld &
// Schnitzlein). A period the scene repeats is taken; another is refused, and so is a container
// with walls where the file's box is periodic.
TEST(Scene, AnImportedBedKeepsTheFilesPeriodInTheScenesContainer) {
  const std::filesystem::path dir = test_support::fresh_dir("scene_import_period", true);
  const auto dump = [&](const std::string& name, const std::string& flags) {
    std::ofstream(dir / name) << "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS " << flags
                              << "\n-2 2\n-2 2\n0 4\nITEM: ATOMS id type x y z diameter\n"
                                 "1 1 0 0 0.5 1\n2 1 0.5 0 1.6 1\n3 1 -0.5 0 2.7 1\n";
  };
  dump("section.dump", "ff ff pp");
  dump("box.dump", "pp pp pp");
  dump("lateral.dump", "pp pp ff");
  const auto scene = [](const std::string& file, const std::string& container) {
    return "[packing]\nalgorithm = \"import\"\nformat = \"lammps-dump\"\nunits = \"mm\"\nfile = \"" + file + "\"\n" +
           container + "[outputs]\nfiles = [\"positions\"]\n";
  };
  const Scene section = read(scene("section.dump", "[container]\ndiameter_d = 4\n"), dir);
  EXPECT_NE(dynamic_cast<const Cylinder*>(section.container.get()), nullptr);
  EXPECT_DOUBLE_EQ(section.container->axial_period(), 0.004);
  EXPECT_DOUBLE_EQ(read(scene("section.dump", "[container]\ndiameter_d = 4\nperiod_z_d = 4\n"), dir)
                       .container->axial_period(),
                   0.004);
  const std::string other = message(scene("section.dump", "[container]\ndiameter_d = 4\nperiod_z_d = 5\n"), dir);
  EXPECT_NE(other.find("container.period_z"), std::string::npos) << other;
  EXPECT_NE(other.find("0.004"), std::string::npos) << other;
  const std::string walls = message(scene("box.dump", "[container]\ndiameter_d = 4\n"), dir);
  EXPECT_NE(walls.find("periodic across x and y"), std::string::npos) << walls;
#ifdef BEDFORGE_HAVE_CGAL
  // Cut through at its planes, its seam depth is in the file's diameters (it read NaN before).
  std::string stl = scene("section.dump", "[container]\ndiameter_d = 4\n");
  stl.replace(stl.find("\"positions\""), 11, "\"stl\"");
  const std::string cut = message(stl + "[contacts]\ntreatment = \"bridge\"\nat_periodic_planes = \"cut\"\n", dir);
  EXPECT_EQ(cut, "accepted");
#endif
  // Without a [container] the file's box is the container, periodic where the file is.
  const Periodicity box = read(scene("box.dump", ""), dir).container->periodicity();
  EXPECT_TRUE(box.lx > 0.0 && box.ly > 0.0 && box.lz > 0.0);
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // A file's box periodic across x and y but walled along z cannot be meshed; the refusal names
  // the file and its sides, not container keys the scene does not have.
  std::string lateral = scene("lateral.dump", "");
  lateral.replace(lateral.find("\"positions\""), 11, "\"stl\"");
  const std::string walled_z = message(lateral, dir);
  EXPECT_NE(walled_z.find("packing.file"), std::string::npos) << walled_z;
  EXPECT_NE(walled_z.find("walled along z"), std::string::npos) << walled_z;
  EXPECT_EQ(walled_z.find("container."), std::string::npos) << walled_z;
#endif
}

TEST(Scene, UnknownSectionsAndOutputsAreRejected) {
  EXPECT_THROW(read("[container]\ndiameter_d = 5\n[particles]\ncount = 10\n[mesh]\nsize_d = 1\n"), InputError);
  EXPECT_THROW(read("[container]\ndiameter_d = 5\n[particles]\ncount = 10\n[outputs]\nfiles = [\"openfoam\"]\n"),
               InputError);
}

TEST(Scene, MomentumBoundIsZeroOrAtLeastOne) {
  const std::string base = "[container]\ndiameter_d = 5\n[particles]\ncount = 10\n[packing.soft_sphere]\n";
  EXPECT_EQ(read(base + "final_momentum_bound = 0\n").soft_sphere.final_momentum_bound, 0.0);
  EXPECT_EQ(read(base + "final_momentum_bound = 1\n").soft_sphere.final_momentum_bound, 1.0);
  for (const char* bad : {"0.5", "-1"}) {
    try {
      read(base + "final_momentum_bound = " + bad + "\n");
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("final_momentum_bound"), std::string::npos) << e.what();
    }
  }
}

#ifdef BEDFORGE_HAVE_CGAL
TEST(Scene, ContactTreatmentsAndTheirErrors) {
  const std::string base = "[container]\ndiameter_d = 5\n[particles]\ncount = 10\n";
  const Scene s = read(base + "[contacts]\ntreatment = \"cap\"\ncap_gap_d = 0.03\n");
  EXPECT_EQ(s.surface.treatment, meshing::SurfaceParams::Treatment::cap);
  EXPECT_EQ(s.surface.wall_treatment, meshing::SurfaceParams::Treatment::cap);  // "same" by default
  EXPECT_DOUBLE_EQ(s.surface.cap_gap_d, 0.03);
  // A clip window cuts through the contacts its planes cross unless told to open them.
  EXPECT_TRUE(read(base + "[surface]\nclip_window_d = [1, 3]\n").surface.cut_at_clip_planes);
  EXPECT_FALSE(read(base + "[contacts]\nat_clip_planes = \"open\"\n[surface]\nclip_window_d = [1, 3]\n").surface.cut_at_clip_planes);
  EXPECT_EQ(read(base + "[contacts]\ntreatment = \"bridge\"\nwall_treatment = \"none\"\n").surface.wall_treatment,
            meshing::SurfaceParams::Treatment::none);
  for (const auto& [bad, names] : std::vector<std::pair<std::string, std::string>>{
           {"treatment = \"glue\"", "contacts.treatment"},
           {"treatment = \"shrink\"\nwall_treatment = \"bridge\"", "contacts.wall_treatment"},
           {"bridge_diameter_d = 0.9", "contacts.bridge_diameter_d"},
           {"cap_gap_d = 0", "contacts.cap_gap_d"},
           {"at_clip_planes = \"slice\"", "contacts.at_clip_planes"},
           {"at_clip_planes = \"cut\"", "contacts.at_clip_planes = \"cut\" without surface.clip_window_d"}}) {
    try {
      read(base + "[contacts]\n" + bad + "\n");
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
    }
  }
}
#endif

#ifdef BEDFORGE_HAVE_VOLUME_MESH
// A plane between slabs cuts through the bed: every contact treatment is cut there (bridges,
// caps and unions from the whole surface), but prism layers would meet it, so slabs are refused
// with them, naming the key; pieces on ranks of their own are cut from widened windows whose
// curved walls are ringed at the planes, so treated contacts are refused in pieces only in a
// box, whose flat sides are not ringed.
TEST(Scene, SlabsAndPiecesAreRefusedWhereTheirPlanesWouldChangeTheBed) {
  const std::string bed = "[container]\ndiameter_d = 5\n[particles]\ncount = 10\n";
  EXPECT_EQ(read(bed + "[contacts]\ntreatment = \"shrink\"\n[mesh]\nslabs = 3\n").mesh.slabs, 3);
  EXPECT_EQ(read(bed + "[contacts]\ntreatment = \"bridge\"\n[mesh]\nslabs = 3\n").mesh.slabs, 3);
  EXPECT_EQ(read(bed + "[contacts]\ntreatment = \"cap\"\n[mesh]\nslabs = 2\n").mesh.slabs, 2);
  EXPECT_EQ(read(bed + "[mesh]\npieces = 2\n").mesh.pieces, 2);  // bridged by default
  const std::string box = "[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\n[particles]\ncount = 10\n";
  EXPECT_EQ(read(box + "[contacts]\ntreatment = \"shrink\"\n[mesh]\npieces = 2\n").mesh.pieces, 2);
  for (const auto& [extra, key] : std::vector<std::pair<std::string, std::string>>{
           {bed + "[contacts]\ntreatment = \"shrink\"\n[mesh]\nslabs = 2\n[mesh.layers]\ncount = 2\n", "mesh.slabs = 2"},
           {bed + "[mesh]\npieces = 2\n[mesh.layers]\ncount = 2\n", "mesh.pieces = 2 with mesh.layers.count = 2"},
           {box + "[mesh]\npieces = 2\n", "mesh.pieces = 2 in a box with contacts.treatment \"bridge\""}}) {
    const std::string m = message(extra);
    EXPECT_NE(m.find(key), std::string::npos) << m;
    EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  }
}
#endif

// The particles' drag by gap: ascending band edges, read; out of order, too many, with
// snappyHexMesh's cells or in pieces, refused naming the key and what is allowed.
TEST(Scene, DragByGapTakesAscendingEdgesOnOnePieceOfGmshCells) {
  const std::string bed = "[container]\ndiameter_d = 5\n[particles]\ncount = 10\n";
  const std::vector<double> edges = {0.01, 0.1};
  EXPECT_EQ(read(bed + "[case]\ndrag_by_gap_d = [0.01, 0.1]\n").case_params.drag_by_gap_d, edges);
  for (const auto& [extra, key] : std::vector<std::pair<std::string, std::string>>{
           {"[case]\ndrag_by_gap_d = [0.1, 0.01]\n", "case.drag_by_gap_d = [0.1, 0.01]"},
           {"[case]\ndrag_by_gap_d = [0.1, 0.1]\n", "case.drag_by_gap_d = [0.1, 0.1]"},
           {"[case]\ndrag_by_gap_d = [1, 2, 3, 4, 5, 6, 7, 8]\n", "up to 7 band edges"},
           {"[case]\ndrag_by_gap_d = [0, 0.1]\n", "drag_by_gap_d"},
           {"[case]\nmesher = \"snappy\"\ndrag_by_gap_d = [0.1]\n", "case.drag_by_gap_d with case.mesher"},
           {"[mesh]\npieces = 2\n[case]\ndrag_by_gap_d = [0.1]\n", "mesh.pieces = 2 with case.drag_by_gap_d"}}) {
    const std::string m = message(bed + extra);
    EXPECT_NE(m.find(key), std::string::npos) << m;
    EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  }
}

TEST(Scene, PeriodicSectionsRefuseWhatTheyCannotBeGiven) {
  const std::string section = "[container]\ndiameter_d = 5\nperiod_z_d = 5\n[particles]\ncount = 105\n";
  EXPECT_EQ(read(section).container->axial_period(), 0.005);
  // A packer that settles on a floor and more spheres than a random packing holds (0.70 solid);
  // each names the period's key and what is allowed. The Monte Carlo packer compresses instead.
  const std::string m = message(section + "[packing.soft_sphere]\nmode = \"faithful\"\n");
  EXPECT_NE(m.find("container.period_z_d is set"), std::string::npos) << m;
  EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  EXPECT_EQ(read(section + "[packing]\nalgorithm = \"monte-carlo\"\n").algorithm, "monte-carlo");
  const std::string jam = message("[container]\ndiameter_d = 5\nperiod_z_m = 0.004\n[particles]\ncount = 105\n"
                                  "[packing]\nalgorithm = \"monte-carlo\"\n");
  EXPECT_NE(jam.find("0.64"), std::string::npos) << jam;
  const std::string full = message("[container]\ndiameter_d = 5\nperiod_z_m = 0.004\n[particles]\ncount = 105\n");
  EXPECT_NE(full.find("container.period_z_m"), std::string::npos) << full;
  EXPECT_NE(full.find("0.64"), std::string::npos) << full;
#ifdef BEDFORGE_HAVE_VOLUME_MESH
  // Its cyclic case: from spheres cut by the periodic planes, in one piece.
  const std::string meshed = section + "[contacts]\ntreatment = \"shrink\"\n[outputs]\nfiles = [\"case\"]\n";
  EXPECT_EQ(read(meshed).container->axial_period(), 0.005);
  for (const auto& [extra, key] : std::vector<std::pair<std::string, std::string>>{
           {"[mesh]\nslabs = 2\n", "mesh.slabs = 2"},
           {"[mesh.layers]\ncount = 2\n", "mesh.layers.count = 2"},
           {"[case]\nmesher = \"snappy\"\n", "case.mesher"},
           {"[case]\ncells = \"tetrahedra\"\n", "case.cells = \"tetrahedra\""}}) {
    const std::string m = message(meshed + extra);
    EXPECT_NE(m.find(key), std::string::npos) << m;
    EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  }
  // Bridged by default: read (the planes open the bridges they cross); enlarge is refused.
  EXPECT_EQ(read(section + "[outputs]\nfiles = [\"case\"]\n").container->axial_period(), 0.005);
  const std::string enlarged = message(section + "[contacts]\ntreatment = \"enlarge\"\n[outputs]\nfiles = [\"case\"]\n");
  EXPECT_NE(enlarged.find("contacts.treatment = \"enlarge\""), std::string::npos) << enlarged;
  // Cut through at the planes: read on this section; refused without a period, and where the
  // period is shorter than twice the seam (an edge of 0.9 d: 4 edges, so 7.2 d).
  const std::string cut = "[contacts]\nat_periodic_planes = \"cut\"\n[outputs]\nfiles = [\"case\"]\n";
  EXPECT_TRUE(read(section + cut).surface.cut_at_periodic_planes);
  // Enlarged, refused above with the planes opening, read when they cut through.
  EXPECT_NE(enlarged.find("at_periodic_planes = \"cut\""), std::string::npos) << enlarged;
  const std::string enlarged_cut = "[contacts]\ntreatment = \"enlarge\"\nat_periodic_planes = \"cut\"\n[outputs]\nfiles = [\"case\"]\n";
  EXPECT_TRUE(read(section + enlarged_cut).surface.cut_at_periodic_planes);
  const std::string unperiodic = message("[container]\ndiameter_d = 5\n[particles]\ncount = 105\n" + cut);
  EXPECT_NE(unperiodic.find("contacts.at_periodic_planes = \"cut\" without container.period_z_d"), std::string::npos)
      << unperiodic;
  // In a box, bridges, caps and enlarged spheres are cut through alike.
  const std::string box = "[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiod_z_d = 4\n[particles]\ncount = 60\n";
  EXPECT_TRUE(read(box + cut).surface.cut_at_periodic_planes);
  EXPECT_TRUE(read(box + enlarged_cut).surface.cut_at_periodic_planes);
  const std::string short_period = message(section + cut + "[surface]\nedge_length_d = 0.9\n");
  EXPECT_NE(short_period.find("container.period_z_d = 5"), std::string::npos) << short_period;
  EXPECT_NE(short_period.find("at least 7.2 d"), std::string::npos) << short_period;
#endif
}

#ifdef BEDFORGE_HAVE_VOLUME_MESH
// A box periodic on every side is meshed with its spheres apart (none or shrink); one periodic on
// one side, or on both without a period along z, is not meshed; each refused by key.
TEST(Scene, ABoxPeriodicOnEverySideRefusesWhatItCannotBeGiven) {
  const std::string box = "[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiodic_x = true\n"
                          "periodic_y = true\nperiod_z_d = 4\n[particles]\ncount = 40\n[packing]\n"
                          "algorithm = \"monte-carlo\"\n[outputs]\nfiles = [\"case\"]\n";
  EXPECT_EQ(read(box + "[contacts]\ntreatment = \"shrink\"\n").surface.treatment, meshing::SurfaceParams::Treatment::shrink);
  for (const auto& [text, says] : std::vector<std::pair<std::string, std::string>>{
           {box, "contacts.treatment = \"bridge\" in a box periodic on every side"},
           {"[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiodic_x = true\nperiod_z_d = 4\n"
            "[particles]\ncount = 40\n[contacts]\ntreatment = \"shrink\"\n[outputs]\nfiles = [\"stl\"]\n",
            "periodic_y = false"},
           {"[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiodic_x = true\nperiodic_y = true\n"
            "[particles]\ncount = 40\n[contacts]\ntreatment = \"shrink\"\n[outputs]\nfiles = [\"stl\"]\n",
            "period_z_d not set"},
           {"[container]\ntype = \"box\"\nsize_x_d = 4\nsize_y_d = 4\nperiodic_x = true\nperiodic_y = true\n"
            "period_z_d = 4\n[particles]\ncount = 0\n[contacts]\ntreatment = \"shrink\"\n[outputs]\nfiles = [\"case\"]\n",
            "particles.count = 0"}}) {
    const std::string m = message(text);
    EXPECT_NE(m.find(says), std::string::npos) << m;
    EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  }
}
#endif

TEST(Scene, ATargetVoidFractionMakesAPeriodicSection) {
  // 212 unit spheres in a = 5 at 0.4347: the period of scenes/examples/periodic_section.toml, 10 d.
  const std::string target = "[container]\ndiameter_m = 0.01\n[particles]\ncount = 212\ndiameter_m = 0.002\n"
                             "[packing.soft_sphere]\ntarget_void_fraction = 0.4347\n";
  EXPECT_NEAR(read(target).container->axial_period(), 0.02, 1e-5);
  // With a period as well, another packer, too few spheres for 3 diameters, a target below random
  // close packing: each refused naming the key and what is allowed.
  for (const auto& [text, says] :
       std::vector<std::pair<std::string, std::string>>{
           {"[container]\ndiameter_m = 0.01\nperiod_z_d = 10\n" + target.substr(target.find("[particles]")), "both set"},
           {target + "[packing]\nalgorithm = \"monte-carlo\"\n", "accelerated soft-sphere packer"},
           {"[container]\ndiameter_d = 5\n[particles]\ncount = 20\n[packing.soft_sphere]\n"
            "target_void_fraction = 0.45\n",
            "shorter than 3 largest diameters"},
           {"[container]\ndiameter_d = 5\n[particles]\ncount = 200\n[packing.soft_sphere]\n"
            "target_void_fraction = 0.3\n",
            "[0.36, 1)"}}) {
    const std::string m = message(text);
    EXPECT_NE(m.find("target_void_fraction"), std::string::npos) << m;
    EXPECT_NE(m.find(says), std::string::npos) << m;
    EXPECT_NE(m.find("allowed"), std::string::npos) << m;
  }
}

// The cluster guide's scene (docs/cluster.md), which no test can run here (1e5 spheres on 256
// ranks), is read as a case in pieces is: its keys exist and its settings are ones pieces allow.
TEST(Scene, TheClusterGuidesSceneIsACaseInPieces) {
  const Scene s = read_scene_file(std::filesystem::path(BEDFORGE_SOURCE_DIR) / "docs/cluster/column_1e5.toml");
  EXPECT_EQ(s.count, 100000);
  EXPECT_EQ(s.mesh.pieces, 256);
  EXPECT_EQ(s.surface.treatment, meshing::SurfaceParams::Treatment::shrink);
  EXPECT_TRUE(s.wants("case"));
  EXPECT_TRUE(s.case_params.run);
}
