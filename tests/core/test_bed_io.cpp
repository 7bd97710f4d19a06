#include "core/bed_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  const fs::path d = test_support::process_temp_dir() / "bed_io";
  fs::create_directories(d);
  return d;
}

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST(BedIo, CsvRoundTripIsBitExactAndKeepsProvenance) {
  Bed bed;
  bed.container = std::make_shared<Cylinder>(0.0125);
  bed.centres = {{0.1, -0.2 / 3.0, 1.0 / 7.0}, {1e-7, 2e-9, 0.0015}};
  bed.diameters = {0.003, 0.0029999999999999996};
  const fs::path p = temp_dir() / "bed.csv";
  write_file_atomically(p, bed_to_csv(bed, {"9.9.9", 42ULL, nlohmann::json{{"particles", {{"count", 2}}}}}));
  const ImportedBed back = read_bed_text(p, 1.0);
  ASSERT_EQ(back.bed.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.bed.centres[i], bed.centres[i]);
    EXPECT_EQ(back.bed.diameters[i], bed.diameters[i]);
  }
  ASSERT_TRUE(back.bed.container);
  EXPECT_DOUBLE_EQ(dynamic_cast<const Cylinder&>(*back.bed.container).radius(), 0.0125);
  EXPECT_EQ(back.header["seed"], 42);
  EXPECT_EQ(back.header["version"], "9.9.9");
  EXPECT_EQ(back.header["scene"]["particles"]["count"], 2);
}

// An empty container (particles.count = 0) keeps the scene's particle diameter, the unit of its
// _d lengths, through its bed.csv; a file of no rows without that header is still refused.
TEST(BedIo, AnEmptyBedKeepsItsReferenceDiameter) {
  Bed bed;
  bed.container = std::make_shared<Cylinder>(0.003);
  bed.reference_diameter_m = 0.0029999999999999996;
  EXPECT_EQ(reference_diameter(bed), bed.reference_diameter_m);
  EXPECT_EQ(largest_diameter(bed), bed.reference_diameter_m);
  const fs::path p = temp_dir() / "empty_bed.csv";
  write_file_atomically(p, bed_to_csv(bed, {"9.9.9", 1ULL, nullptr}));
  const ImportedBed back = read_bed_text(p, 1.0);
  EXPECT_EQ(back.bed.size(), 0u);
  EXPECT_EQ(reference_diameter(back.bed), bed.reference_diameter_m);
  ASSERT_TRUE(back.bed.container);
  // With spheres, the reference is theirs unless the bed keeps one (a window of a larger bed), and
  // no such header line is written.
  bed.centres = {{0.0, 0.0, 0.001}};
  bed.diameters = {0.002};
  EXPECT_EQ(reference_diameter(bed), 0.0029999999999999996);
  bed.reference_diameter_m = 0.0;
  EXPECT_EQ(reference_diameter(bed), 0.002);
  EXPECT_EQ(bed_to_csv(bed, {"9.9.9", 1ULL, nullptr}).find("reference_diameter_m"), std::string::npos);
}

TEST(BedIo, ReadsSpacesTabsSemicolonsAndAColumnHeaderInMillimetres) {
  const auto p = write("dem.txt", "x y z d\n1 2 3 4\n5\t6\t7\t8\r\n9;10;11;12\n\n");
  const ImportedBed b = read_bed_text(p, 1e-3);
  ASSERT_EQ(b.bed.size(), 3u);
  EXPECT_DOUBLE_EQ(b.bed.centres[1].y(), 6e-3);
  EXPECT_DOUBLE_EQ(b.bed.diameters[2], 12e-3);
  EXPECT_FALSE(b.bed.container);
}

TEST(BedIo, BadRowsNameFileLineAndField) {
  try {
    read_bed_text(write("bad1.txt", "1 2 3 4\n1 2 3\n"), 1.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad1.txt:2"), std::string::npos) << e.what();
  }
  try {
    read_bed_text(write("bad2.txt", "1 2 3 -4\n"), 1.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("d = -4"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_bed_text(write("bad3.txt", "1 2 nan 4\n"), 1.0), InputError);
  EXPECT_THROW(read_bed_text(write("empty.txt", "# nothing\n"), 1.0), InputError);
  EXPECT_THROW(read_bed_text(temp_dir() / "missing.txt", 1.0), InputError);
}

TEST(BedIo, VtpHasOneVertexAndDiameterPerSphere) {
  Bed bed;
  bed.container = std::make_shared<Cylinder>(1.0);
  bed.centres = {{0, 0, 0.5}, {0, 0, 1.5}, {0.2, 0, 2.5}};
  bed.diameters = {1, 1, 1};
  const std::string vtp = bed_to_vtp(bed, {"v", 1ULL, nullptr});
  EXPECT_NE(vtp.find("NumberOfPoints=\"3\""), std::string::npos);
  EXPECT_NE(vtp.find("Name=\"diameter\""), std::string::npos);
  EXPECT_EQ(vtp.find("--", vtp.find("<!--") + 4), vtp.find("-->"));  // no "--" inside the comment
}
