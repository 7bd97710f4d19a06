#include "cases/poly_mesh_io.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <type_traits>

namespace bedforge::cases {

std::string foam_header(const std::string& cls, const std::string& location, const std::string& object,
                        const std::string& note, bool binary) {
  return fmt::format(
      "/*--------------------------------*- C++ -*----------------------------------*\\\n"
      "  written by bedforge for OpenFOAM v1912\n"
      "\\*---------------------------------------------------------------------------*/\n"
      "FoamFile\n{{\n    version     2.0;\n    format      {};\n    arch        \"LSB;label=32;scalar=64\";\n"
      "    class       {};\n    location    \"{}\";\n    object      {};\n    note        \"{}\";\n}}\n\n",
      binary ? "binary" : "ascii", cls, location, object, note);
}

namespace {

std::ofstream open(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  return out;
}

// A list of N items: `N\n(` raw bytes `)` in binary, one item per line in ASCII.
template <class T, class Ascii>
void write_list(std::ostream& out, const std::vector<T>& items, bool binary, Ascii ascii) {
  out << items.size() << "\n(";
  if (binary) {
    out.write(reinterpret_cast<const char*>(items.data()), static_cast<std::streamsize>(items.size() * sizeof(T)));
  } else {
    out << "\n";
    std::string buf;
    for (const T& x : items) {
      buf.clear();
      ascii(buf, x);
      out << buf << "\n";
    }
  }
  out << ")\n";
}

}  // namespace

namespace {

// Both meshes have the same members; their faces differ in how they are stored.
template <class Mesh>
void write_mesh(const std::filesystem::path& dir, const Mesh& m, bool binary, const std::string& note) {
  std::filesystem::create_directories(dir);
  const std::string loc = "constant/polyMesh";
  {
    auto out = open(dir / "points");
    out << foam_header("vectorField", loc, "points", note, binary);
    static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
    write_list(out, m.points, binary, [](std::string& b, const Eigen::Vector3d& p) {
      fmt::format_to(std::back_inserter(b), "({:.17g} {:.17g} {:.17g})", p.x(), p.y(), p.z());  // round-trips exactly
    });
  }
  {
    auto out = open(dir / "faces");
    if (binary) {
      // Binary faces are a compact list: N+1 offsets, then the vertex labels of all faces.
      out << foam_header("faceCompactList", loc, "faces", note, true);
      if constexpr (std::is_same_v<Mesh, meshing::PolyhedralMesh>) {
        write_list(out, m.faces.offsets, true, [](std::string&, std::int32_t) {});
        out << "\n";
        write_list(out, m.faces.points, true, [](std::string&, std::int32_t) {});
      } else {
        meshing::Polygons compact;
        compact.offsets.reserve(m.faces.size() + 1);
        compact.points.reserve(3 * m.faces.size());
        for (const auto& f : m.faces) compact.push_back(std::span<const int>(f.begin(), f.end()));
        write_list(out, compact.offsets, true, [](std::string&, std::int32_t) {});
        out << "\n";
        write_list(out, compact.points, true, [](std::string&, std::int32_t) {});
      }
    } else {
      out << foam_header("faceList", loc, "faces", note, false);
      out << m.faces.size() << "\n(\n";
      for (std::size_t f = 0; f < m.faces.size(); ++f) {
        const auto& face = m.faces[f];
        out << fmt::format("{}({})\n", face.size(), fmt::join(face.begin(), face.end(), " "));
      }
      out << ")\n";
    }
  }
  const std::string sizes = fmt::format("nPoints:{}  nCells:{}  nFaces:{}  nInternalFaces:{}", m.points.size(), m.cells,
                                        m.faces.size(), m.internal_faces());
  for (const auto& [name, list] : {std::pair{"owner", &m.owner}, std::pair{"neighbour", &m.neighbour}}) {
    auto out = open(dir / name);
    out << foam_header("labelList", loc, name, note + "; " + sizes, binary);
    static_assert(sizeof(int) == sizeof(std::int32_t));
    write_list(out, *list, binary, [](std::string& b, int v) { fmt::format_to(std::back_inserter(b), "{}", v); });
  }
  auto out = open(dir / "boundary");
  out << foam_header("polyBoundaryMesh", loc, "boundary", note, false);
  out << m.patches.size() << "\n(\n";
  for (const auto& p : m.patches) {
    out << fmt::format("    {}\n    {{\n        type            {};\n", p.name, p.type);
    if (p.type == "wall") out << "        inGroups        List<word> 1(wall);\n";
    if (p.type == "cyclic")
      out << fmt::format("        inGroups        List<word> 1(cyclic);\n        matchTolerance  0.0001;\n"
                         "        transform       translational;\n        neighbourPatch  {};\n"
                         "        separationVector ({:.17g} {:.17g} {:.17g});\n",
                         p.neighbour, p.separation.x(), p.separation.y(), p.separation.z());
    if (p.type == "processor")
      out << fmt::format("        inGroups        List<word> 1(processor);\n        matchTolerance  0.0001;\n"
                         "        transform       unknown;\n        myProcNo        {};\n        neighbProcNo    {};\n",
                         p.processor, p.neighbour_processor);
    out << fmt::format("        nFaces          {};\n        startFace       {};\n    }}\n", p.size, p.start);
  }
  out << ")\n";
}

}  // namespace

void write_poly_mesh(const std::filesystem::path& dir, const meshing::PolyMesh& mesh, bool binary,
                     const std::string& note) {
  write_mesh(dir, mesh, binary, note);
}

void write_poly_mesh(const std::filesystem::path& dir, const meshing::PolyhedralMesh& mesh, bool binary,
                     const std::string& note) {
  write_mesh(dir, mesh, binary, note);
}

}  // namespace bedforge::cases
