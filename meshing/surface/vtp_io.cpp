#include "meshing/surface/vtp_io.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <vector>

namespace bedforge::meshing {

namespace {

// Bytes of one block of appended data: its UInt64 byte count, then the values.
template <class T>
std::size_t block_bytes(const std::vector<T>& values) {
  return sizeof(std::uint64_t) + values.size() * sizeof(T);
}

template <class T>
void write_block(std::ostream& out, const std::vector<T>& values) {
  const std::uint64_t bytes = values.size() * sizeof(T);
  out.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(bytes));
}

}  // namespace

void write_vtp(std::ostream& out, const TriangleMesh& m, const std::string& comment) {
  static_assert(std::endian::native == std::endian::little, "the .vtp writer declares little-endian data");
  std::vector<double> xyz;
  xyz.reserve(3 * m.points.size());
  for (const auto& p : m.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  std::vector<std::int64_t> connectivity, offsets;
  connectivity.reserve(3 * m.triangles.size());
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    for (int v : m.triangles[k]) connectivity.push_back(v);
    offsets.push_back(static_cast<std::int64_t>(3 * (k + 1)));
  }
  const std::vector<std::int32_t> patch(m.patch.begin(), m.patch.end());
  // Offset of each block in the appended section, in the order they are written below.
  const std::size_t at[4] = {0, block_bytes(patch), block_bytes(patch) + block_bytes(xyz),
                             block_bytes(patch) + block_bytes(xyz) + block_bytes(connectivity)};

  std::string names;
  for (std::size_t p = 0; p < m.patches.size(); ++p) names += fmt::format("  patch {} = {}\n", p, m.patches[p]);
  std::string note = comment + "\n" + names;
  for (std::size_t k; (k = note.find("--")) != std::string::npos;) note.replace(k, 2, "- ");  // not allowed in a comment
  out << "<?xml version=\"1.0\"?>\n<!--\n" << note << "-->\n"
      << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PolyData>\n"
      << "<FieldData>\n";
  for (std::size_t p = 0; p < m.patches.size(); ++p)
    out << fmt::format("<DataArray type=\"Int32\" Name=\"patch_{}\" NumberOfTuples=\"1\" format=\"ascii\">{}</DataArray>\n",
                       m.patches[p], p);
  out << "</FieldData>\n"
      << fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
                     "NumberOfPolys=\"{}\">\n",
                     m.points.size(), m.triangles.size())
      << fmt::format("<CellData Scalars=\"patch\">\n<DataArray type=\"Int32\" Name=\"patch\" format=\"appended\" "
                     "offset=\"{}\"/>\n</CellData>\n",
                     at[0])
      << fmt::format("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" "
                     "offset=\"{}\"/>\n</Points>\n",
                     at[1])
      << fmt::format("<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n"
                     "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n</Polys>\n",
                     at[2], at[3])
      << "</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";
  write_block(out, patch);
  write_block(out, xyz);
  write_block(out, connectivity);
  write_block(out, offsets);
  out << "\n</AppendedData>\n</VTKFile>\n";
}

}  // namespace bedforge::meshing
