#include "core/dem_import.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "support/input_error.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
using input_error_test::error_of;
namespace fs = std::filesystem;

namespace {

fs::path write(const std::string& name, const std::string& text) {
  const fs::path d = test_support::process_temp_dir() / "dem_import";
  fs::create_directories(d);
  std::ofstream(d / name) << text;
  return d / name;
}


// A LAMMPS/LIGGGHTS `dump custom` snapshot of two spheres: the first in box-scaled coordinates
// when `scaled`, the radius column after the coordinates as LIGGGHTS writes it.
std::string snapshot(long step, double z_shift, bool scaled) {
  std::string s = "ITEM: TIMESTEP\n" + std::to_string(step) + "\nITEM: NUMBER OF ATOMS\n2\n";
  s += "ITEM: BOX BOUNDS ff ff ff\n-10 10\n-10 10\n0 40\n";
  if (scaled) {
    s += "ITEM: ATOMS id type xs ys zs vx radius\n";
    s += "1 1 0.5 0.25 " + std::to_string((1.5 + z_shift) / 40.0) + " 0 1.5\n";
    s += "2 1 0.6 0.5 0.1 0 1.5\n";
  } else {
    s += "ITEM: ATOMS id type x y z vx radius\n";
    s += "1 1 0 -5 " + std::to_string(1.5 + z_shift) + " 0 1.5\n";
    s += "2 1 2 0 4 0 1.5\n";
  }
  return s;
}

}  // namespace

TEST(DemImport, LammpsDumpReadsTheLastSnapshotAndDoublesTheRadius) {
  const fs::path p = write("two.dump", snapshot(0, 20.0, false) + snapshot(5000, 0.0, false));
  const ImportedBed in = read_lammps_dump(p, 1e-3);  // millimetres
  ASSERT_EQ(in.bed.size(), 2u);
  EXPECT_EQ(in.header["snapshots"], 2);
  EXPECT_EQ(in.header["timestep"], 5000);
  EXPECT_NEAR(in.bed.centres[0].z(), 1.5e-3, 1e-15);  // the settled snapshot, not the first
  EXPECT_NEAR(in.bed.centres[0].y(), -5e-3, 1e-15);
  EXPECT_NEAR(in.bed.diameters[1], 3e-3, 1e-15);
}

TEST(DemImport, ScaledCoordinatesAreMappedThroughTheBox) {
  const ImportedBed in = read_lammps_dump(write("scaled.dump", snapshot(1, 0.0, true)), 1.0);
  ASSERT_EQ(in.bed.size(), 2u);
  // xs = 0.5 in [-10, 10] is 0; ys = 0.25 is -5; zs = 1.5 / 40 in [0, 40] is 1.5.
  EXPECT_NEAR(in.bed.centres[0].x(), 0.0, 1e-12);
  EXPECT_NEAR(in.bed.centres[0].y(), -5.0, 1e-12);
  EXPECT_NEAR(in.bed.centres[0].z(), 1.5, 1e-12);
  EXPECT_NEAR(in.bed.centres[1].x(), 2.0, 1e-12);
}

TEST(DemImport, APeriodicBoxBecomesTheContainer) {
  // A box periodic on every side, [0, 8] x [2, 10] x [-1, 7] mm: the container is a box of 8 mm
  // periodic in x and y with an axial period of 8 mm, in bedforge's frame (centred in x and y,
  // z from the lower bound); a box with walls (flags ff) keeps no container, as before.
  const std::string dump = "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 8\n2 10\n-1 7\n"
                           "ITEM: ATOMS id type x y z radius\n1 1 1 3 0 0.5\n";
  const ImportedBed in = read_lammps_dump(write("periodic.dump", dump), 1e-3);
  ASSERT_NE(in.bed.container, nullptr);
  const Periodicity per = in.bed.container->periodicity();
  EXPECT_NEAR(per.lx, 8e-3, 1e-15);
  EXPECT_NEAR(per.ly, 8e-3, 1e-15);
  EXPECT_NEAR(per.lz, 8e-3, 1e-15);
  EXPECT_NEAR(in.bed.centres[0].x(), -3e-3, 1e-15);
  EXPECT_NEAR(in.bed.centres[0].y(), -3e-3, 1e-15);
  EXPECT_NEAR(in.bed.centres[0].z(), 1e-3, 1e-15);
  EXPECT_EQ(read_lammps_dump(write("walled.dump", snapshot(1, 0.0, false)), 1.0).bed.container, nullptr);
  std::string tilted = dump;
  tilted.replace(tilted.find("BOUNDS pp pp pp\n0 8\n2 10\n-1 7"), 29, "BOUNDS xy xz yz pp pp pp\n0 8 0\n2 10 0\n-1 7 0");
  EXPECT_NE(error_of([&] { read_lammps_dump(write("tilted.dump", tilted), 1.0); }).find("triclinic"), std::string::npos);
}

TEST(DemImport, LammpsDiameterColumnIsTakenAsIs) {
  const std::string dump =
      "ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n-1 1\n-1 1\n0 2\n"
      "ITEM: ATOMS id diameter x y z\n1 0.002 0.1 0.2 0.001\n";
  const ImportedBed in = read_lammps_dump(write("diameter.dump", dump), 1.0);
  ASSERT_EQ(in.bed.size(), 1u);
  EXPECT_DOUBLE_EQ(in.bed.diameters[0], 0.002);
  EXPECT_DOUBLE_EQ(in.bed.centres[0].x(), 0.1);
}

TEST(DemImport, BrokenDumpsAreRefusedWithTheLine) {
  const std::string head = "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n";
  const struct {
    const char* name;
    std::string text, message;
  } cases[] = {
      {"nor.dump", head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 1\n", "neither radius nor diameter"},
      {"cut.dump", head + "ITEM: ATOMS id x y z radius\n1 0 0 0 1\n", "cut short"},
      {"nan.dump", head + "ITEM: ATOMS x y z radius\n0 0 nan 1\n0 0 1 1\n", "nan.dump:10: z = 'nan'"},
      {"neg.dump", head + "ITEM: ATOMS x y z radius\n0 0 0 -1\n0 0 1 1\n", "diameter -2; allowed: > 0"},
      {"text.dump", "x y z d\n0 0 0 1\n", "no snapshot"},
  };
  for (const auto& c : cases)
    EXPECT_NE(error_of([&] { read_lammps_dump(write(c.name, c.text), 1); }).find(c.message), std::string::npos) << c.name;
}

TEST(DemImport, YadeTextGivesRadiiAndHonoursItsFormatLine) {
  const ImportedBed plain = read_yade_text(write("yade.txt", "#format x_y_z_r\n0 0 0.5 0.5\n1 0 0.5 0.5\n"), 1.0);
  ASSERT_EQ(plain.bed.size(), 2u);
  EXPECT_DOUBLE_EQ(plain.bed.diameters[0], 1.0);
  EXPECT_DOUBLE_EQ(plain.bed.centres[1].x(), 1.0);
  const ImportedBed with_id = read_yade_text(write("yade_id.txt", "#format id_x_y_z_r_matId\n7 1 2 3 0.25 0\n"), 1e-2);
  ASSERT_EQ(with_id.bed.size(), 1u);
  EXPECT_NEAR(with_id.bed.centres[0].x(), 0.01, 1e-15);  // the id column is skipped
  EXPECT_NEAR(with_id.bed.diameters[0], 0.005, 1e-15);
  EXPECT_NE(error_of([&] { read_yade_text(write("yade_bad.txt", "#format r_x_y_z\n1 0 0 0\n"), 1); })
                .find("#format r_x_y_z; allowed"),
            std::string::npos);
  EXPECT_NE(error_of([&] { read_yade_text(write("yade_short.txt", "0 0 1\n"), 1); }).find("yade_short.txt:1"),
            std::string::npos);
}

TEST(DemImport, OriginIsSubtractedAfterTheUnit) {
  const fs::path p = write("shifted.txt", "100 200 1.5 3\n");
  const ImportedBed in = read_bed_file(p, BedFileFormat::xyzd, 1e-3, {0.1, 0.2, 0.0});
  EXPECT_NEAR(in.bed.centres[0].x(), 0.0, 1e-15);
  EXPECT_NEAR(in.bed.centres[0].y(), 0.0, 1e-15);
  EXPECT_NEAR(in.bed.centres[0].z(), 1.5e-3, 1e-15);
  EXPECT_NE(error_of([] { bed_file_format("vtk"); }).find("allowed: xyzd, lammps-dump"), std::string::npos);
}
