#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <regex>
#include <sstream>

#include "meshing/surface/vtp_io.hpp"

using namespace bedforge::meshing;

namespace {

// Reads block `offset` of the raw appended section: a UInt64 byte count, then the values.
template <class T>
std::vector<T> block(const std::string& appended, std::size_t offset) {
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, appended.data() + offset, sizeof bytes);
  std::vector<T> v(bytes / sizeof(T));
  std::memcpy(v.data(), appended.data() + offset + sizeof bytes, bytes);
  return v;
}

std::size_t offset_of(const std::string& xml, const std::string& tag) {
  std::smatch m;
  EXPECT_TRUE(std::regex_search(xml, m, std::regex(tag + "[^>]*offset=\"([0-9]+)\""))) << tag;
  return std::stoul(m[1]);
}

}  // namespace

// Round trip: the points, triangles and patches read back from the appended blocks at the
// offsets the XML names are the mesh written, and ParaView's header fields are consistent.
TEST(Vtp, RoundTripOfALabelledTetrahedron) {
  TriangleMesh m;
  m.points = {{0, 0, 0}, {1e-3, 0, 0}, {0, 2e-3, 0}, {0, 0, 3e-3}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  m.patches = {"inlet", "particles"};
  m.patch = {0, 1, 1, 1};
  std::ostringstream out;
  write_vtp(out, m, "test -- comment");
  const std::string text = out.str();
  const std::size_t underscore = text.find("<AppendedData encoding=\"raw\">\n_");
  ASSERT_NE(underscore, std::string::npos);
  const std::string xml = text.substr(0, underscore), appended = text.substr(text.find('_', underscore) + 1);
  EXPECT_EQ(xml.find("--", xml.find("<!--") + 4), xml.find("-->"));  // no "--" inside the comment
  EXPECT_NE(xml.find("NumberOfPoints=\"4\""), std::string::npos);
  EXPECT_NE(xml.find("NumberOfPolys=\"4\""), std::string::npos);
  EXPECT_NE(xml.find("Name=\"patch_particles\" NumberOfTuples=\"1\" format=\"ascii\">1<"), std::string::npos);

  const auto xyz = block<double>(appended, offset_of(xml, "NumberOfComponents=\"3\""));
  ASSERT_EQ(xyz.size(), 12u);
  for (std::size_t v = 0; v < 4; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(xyz[3 * v + k], m.points[v][k]);
  const auto conn = block<std::int64_t>(appended, offset_of(xml, "Name=\"connectivity\""));
  const auto offs = block<std::int64_t>(appended, offset_of(xml, "Name=\"offsets\""));
  const auto patch = block<std::int32_t>(appended, offset_of(xml, "Name=\"patch\""));
  ASSERT_EQ(conn.size(), 12u);
  ASSERT_EQ(offs.size(), 4u);
  ASSERT_EQ(patch.size(), 4u);
  for (std::size_t t = 0; t < 4; ++t) {
    EXPECT_EQ(offs[t], static_cast<std::int64_t>(3 * (t + 1)));
    EXPECT_EQ(patch[t], m.patch[t]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(conn[3 * t + k], m.triangles[t][k]);
  }
}
