#include "core/bed_io.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace bedforge {

namespace {

std::string header_lines(const Bed& bed, const Provenance& p, const char* prefix) {
  std::string h;
  const bool periodic_axis = bed.container && bed.container->axial_period() > 0.0;
  h += fmt::format("{}bedforge bed: sphere centres and diameters in metres; container axis z through the origin, "
                   "{}\n",
                   prefix, periodic_axis ? "periodic along z, centres in [0, period_z)" : "floor z = 0");
  h += fmt::format("{}version: {}\n", prefix, p.version);
  if (p.seed) h += fmt::format("{}seed: {}\n", prefix, *p.seed);
  if (bed.container) h += fmt::format("{}container_m: {}\n", prefix, bed.container->to_json().dump());
  if (bed.size() == 0) h += fmt::format("{}reference_diameter_m: {:.17g}\n", prefix, bed.reference_diameter_m);
  if (!p.scene.is_null()) h += fmt::format("{}scene: {}\n", prefix, p.scene.dump());
  return h;
}

}  // namespace

std::string bed_to_csv(const Bed& bed, const Provenance& p) {
  std::string out = header_lines(bed, p, "# ");
  out += "x_m,y_m,z_m,d_m\n";
  for (size_t i = 0; i < bed.size(); ++i) {
    const auto& c = bed.centres[i];
    out += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\n", c.x(), c.y(), c.z(), bed.diameters[i]);
  }
  return out;
}

std::string bed_to_vtp(const Bed& bed, const Provenance& p) {
  std::string h = header_lines(bed, p, "  ");
  // "--" may not appear inside an XML comment.
  for (size_t k; (k = h.find("--")) != std::string::npos;) h.replace(k, 2, "- ");
  std::string out = "<?xml version=\"1.0\"?>\n<!--\n" + h + "-->\n";
  const size_t n = bed.size();
  out += "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
  out += fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
                     "NumberOfPolys=\"0\">\n",
                     n, n);
  out += "<PointData Scalars=\"diameter\">\n<DataArray type=\"Float64\" Name=\"diameter\" format=\"ascii\">\n";
  for (double d : bed.diameters) out += fmt::format("{:.17g}\n", d);
  out += "</DataArray>\n<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (double d : bed.diameters) out += fmt::format("{:.17g}\n", 0.5 * d);
  out += "</DataArray>\n</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& c : bed.centres) out += fmt::format("{:.17g} {:.17g} {:.17g}\n", c.x(), c.y(), c.z());
  out += "</DataArray>\n</Points>\n<Verts>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (size_t i = 0; i < n; ++i) out += fmt::format("{}\n", i);
  out += "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (size_t i = 0; i < n; ++i) out += fmt::format("{}\n", i + 1);
  out += "</DataArray>\n</Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  return out;
}

ImportedBed read_bed_text(const std::filesystem::path& path, double to_metres) {
  const std::string text = read_file(path);
  ImportedBed result;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool seen_data = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      // bedforge's own header: restore what made the bed.
      const std::string body = line.substr(first + 1);
      for (const char* key : {"container_m:", "scene:", "version:", "seed:", "reference_diameter_m:"}) {
        const auto k = body.find(key);
        if (k == std::string::npos || body.find_first_not_of(' ') != k) continue;
        const std::string value = body.substr(k + std::string(key).size());
        try {
          if (std::string(key) == "container_m:") result.bed.container = container_from_json(nlohmann::json::parse(value));
          else if (std::string(key) == "scene:") result.header["scene"] = nlohmann::json::parse(value);
          else if (std::string(key) == "seed:") result.header["seed"] = std::stoull(value);
          else if (std::string(key) == "reference_diameter_m:") result.bed.reference_diameter_m = std::stod(value);
          else result.header["version"] = value.substr(value.find_first_not_of(' '));
        } catch (const std::exception& e) {
          throw InputError(fmt::format("{}:{}: unreadable header entry '{}': {}", path.string(), line_no, key, e.what()));
        }
      }
      continue;
    }
    std::string fields = line;
    for (char& ch : fields)
      if (ch == ',' || ch == ';' || ch == '\t') ch = ' ';
    std::istringstream row(fields);
    std::vector<std::string> tokens;
    for (std::string t; row >> t;) tokens.push_back(t);
    std::vector<double> v;
    bool numeric = true;
    for (const auto& t : tokens) {
      try {
        size_t used = 0;
        v.push_back(std::stod(t, &used));
        numeric = numeric && used == t.size();
      } catch (const std::exception&) {
        numeric = false;
      }
    }
    if (!numeric && !seen_data) continue;  // a column-name line
    static const char* names[4] = {"x", "y", "z", "d"};
    if (!numeric || tokens.size() != 4)
      throw InputError(fmt::format("{}:{}: expected 4 numbers 'x y z d', got '{}'", path.string(), line_no, line));
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(v[k]))
        throw InputError(fmt::format("{}:{}: field {} is {}; allowed: a finite number", path.string(), line_no,
                                     names[k], tokens[k]));
    if (!(v[3] > 0))
      throw InputError(fmt::format("{}:{}: diameter d = {}; allowed: d > 0", path.string(), line_no, tokens[3]));
    seen_data = true;
    result.bed.centres.emplace_back(v[0] * to_metres, v[1] * to_metres, v[2] * to_metres);
    result.bed.diameters.push_back(v[3] * to_metres);
  }
  // Only bedforge's own record of an empty container may have no rows.
  if (result.bed.centres.empty() && !(result.bed.reference_diameter_m > 0.0))
    throw InputError(fmt::format("{}: no sphere rows 'x y z d' found", path.string()));
  return result;
}

}  // namespace bedforge
