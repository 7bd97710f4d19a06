#include "core/dem_import.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace bedforge {

namespace {

std::vector<std::string> split_words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// Reads the whole file as lines, with the line numbers InputError messages name.
struct Lines {
  std::vector<std::string> text;
  explicit Lines(const std::filesystem::path& path) {
    std::istringstream in(read_file(path));
    for (std::string line; std::getline(in, line);) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      text.push_back(std::move(line));
    }
  }
};

class RowReader {
 public:
  RowReader(const std::filesystem::path& path) : path_(path.string()) {}
  // Field `k` of `words` as a finite number; InputError names the line and column otherwise.
  double number(const std::vector<std::string>& words, std::size_t k, std::size_t line, const std::string& column) const {
    if (k >= words.size())
      throw InputError(fmt::format("{}:{}: the row has {} fields, no '{}' (field {}); allowed: one value per column",
                                   path_, line, words.size(), column, k + 1));
    try {
      std::size_t used = 0;
      const double v = std::stod(words[k], &used);
      if (used == words[k].size() && std::isfinite(v)) return v;
    } catch (const std::exception&) {
    }
    throw InputError(fmt::format("{}:{}: {} = '{}'; allowed: a finite number", path_, line, column, words[k]));
  }
  void add_sphere(ImportedBed& out, const Eigen::Vector3d& centre, double diameter, std::size_t line,
                  double to_metres) const {
    if (!(diameter > 0.0))
      throw InputError(fmt::format("{}:{}: diameter {}; allowed: > 0", path_, line, diameter));
    out.bed.centres.push_back(centre * to_metres);
    out.bed.diameters.push_back(diameter * to_metres);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::size_t count_of(const std::string& word, const std::string& path, std::size_t line, const char* what) {
  try {
    std::size_t used = 0;
    const long long v = std::stoll(word, &used);
    if (used == word.size() && v >= 0) return static_cast<std::size_t>(v);
  } catch (const std::exception&) {
  }
  throw InputError(fmt::format("{}:{}: {} = '{}'; allowed: an integer >= 0", path, line, what, word));
}

}  // namespace

BedFileFormat bed_file_format(const std::string& name) {
  if (name == "xyzd") return BedFileFormat::xyzd;
  if (name == "lammps-dump") return BedFileFormat::lammps_dump;
  if (name == "yade") return BedFileFormat::yade;
  throw InputError(fmt::format("bed file format '{}'; allowed: xyzd, lammps-dump (also LIGGGHTS), yade", name));
}

const char* bed_file_format_name(BedFileFormat format) {
  switch (format) {
    case BedFileFormat::lammps_dump: return "lammps-dump";
    case BedFileFormat::yade: return "yade";
    case BedFileFormat::xyzd: break;
  }
  return "xyzd";
}

ImportedBed read_lammps_dump(const std::filesystem::path& path, double to_metres) {
  const Lines lines(path);
  const RowReader rows(path);
  ImportedBed last;
  std::size_t snapshots = 0;
  long long timestep = -1;
  std::size_t atoms = 0;
  bool have_atoms_count = false;
  Eigen::Matrix<double, 3, 2> box = Eigen::Matrix<double, 3, 2>::Zero();
  bool triclinic = false;
  std::array<bool, 3> periodic{};  // boundary flags "pp" of the box bounds
  auto line_after = [&](std::size_t i, const char* item) -> const std::string& {
    if (i + 1 >= lines.text.size())
      throw InputError(fmt::format("{}:{}: the file ends after 'ITEM: {}'", rows.path(), i + 1, item));
    return lines.text[i + 1];
  };
  for (std::size_t i = 0; i < lines.text.size(); ++i) {
    const std::string& line = lines.text[i];
    if (line.rfind("ITEM:", 0) != 0) continue;
    const std::vector<std::string> words = split_words(line.substr(5));
    const std::string item = words.empty() ? "" : words[0];
    if (item == "TIMESTEP") {
      const auto w = split_words(line_after(i, "TIMESTEP"));
      timestep = static_cast<long long>(count_of(w.empty() ? "" : w[0], rows.path(), i + 2, "TIMESTEP"));
    } else if (item == "NUMBER") {
      const auto w = split_words(line_after(i, "NUMBER OF ATOMS"));
      atoms = count_of(w.empty() ? "" : w[0], rows.path(), i + 2, "NUMBER OF ATOMS");
      have_atoms_count = true;
    } else if (item == "BOX") {
      triclinic = words.size() > 2 && words[2] == "xy";
      // `ITEM: BOX BOUNDS [xy xz yz] xx yy zz`: the last three words, when given, are the
      // boundary flags (p periodic; f, s, m not).
      for (int k = 0; k < 3; ++k)
        periodic[k] = words.size() >= 5 && words[words.size() - 3 + k] == "pp";
      for (int k = 0; k < 3; ++k) {
        if (i + 1 + k >= lines.text.size())
          throw InputError(fmt::format("{}:{}: the box bounds end early", rows.path(), i + 1));
        const auto w = split_words(lines.text[i + 1 + k]);
        box(k, 0) = rows.number(w, 0, i + 2 + k, "box lower bound");
        box(k, 1) = rows.number(w, 1, i + 2 + k, "box upper bound");
      }
    } else if (item == "ATOMS") {
      if (!have_atoms_count)
        throw InputError(fmt::format("{}:{}: 'ITEM: ATOMS' before 'ITEM: NUMBER OF ATOMS'", rows.path(), i + 1));
      const std::vector<std::string> columns(words.begin() + 1, words.end());
      auto find = [&](std::initializer_list<const char*> names) -> std::optional<std::pair<std::size_t, std::string>> {
        for (const char* name : names)
          for (std::size_t c = 0; c < columns.size(); ++c)
            if (columns[c] == name) return std::make_pair(c, std::string(name));
        return std::nullopt;
      };
      std::optional<std::pair<std::size_t, std::string>> axis[3];
      const char* names[3][4] = {{"x", "xu", "xs", "xsu"}, {"y", "yu", "ys", "ysu"}, {"z", "zu", "zs", "zsu"}};
      for (int k = 0; k < 3; ++k) {
        axis[k] = find({names[k][0], names[k][1], names[k][2], names[k][3]});
        if (!axis[k])
          throw InputError(fmt::format("{}:{}: the ATOMS columns ({}) have no {} coordinate; allowed: {}, {}, {} or {}",
                                       rows.path(), i + 1, fmt::join(columns, " "), names[k][0], names[k][0],
                                       names[k][1], names[k][2], names[k][3]));
        if (axis[k]->second.find('s') != std::string::npos && triclinic)
          throw InputError(fmt::format("{}:{}: scaled coordinates of a triclinic box are not supported; dump x y z "
                                       "instead",
                                       rows.path(), i + 1));
      }
      const auto radius = find({"radius"}), diameter = find({"diameter"});
      if (!radius && !diameter)
        throw InputError(fmt::format("{}:{}: the ATOMS columns ({}) have neither radius nor diameter; add one to the "
                                     "dump command",
                                     rows.path(), i + 1, fmt::join(columns, " ")));
      ImportedBed snap;
      for (std::size_t a = 0; a < atoms; ++a) {
        const std::size_t at = i + 1 + a;
        if (at >= lines.text.size() || lines.text[at].rfind("ITEM:", 0) == 0)
          throw InputError(fmt::format("{}:{}: the snapshot lists {} atoms where NUMBER OF ATOMS says {}; the file "
                                       "is cut short",
                                       rows.path(), at + 1, a, atoms));
        const auto w = split_words(lines.text[at]);
        Eigen::Vector3d c;
        for (int k = 0; k < 3; ++k) {
          c[k] = rows.number(w, axis[k]->first, at + 1, axis[k]->second);
          if (axis[k]->second.find('s') != std::string::npos) c[k] = box(k, 0) + c[k] * (box(k, 1) - box(k, 0));
        }
        const double d = radius ? 2.0 * rows.number(w, radius->first, at + 1, "radius")
                                : rows.number(w, diameter->first, at + 1, "diameter");
        rows.add_sphere(snap, c, d, at + 1, to_metres);
      }
      last = std::move(snap);
      ++snapshots;
      i += atoms;
    }
  }
  if (snapshots == 0 || last.bed.size() == 0)
    throw InputError(fmt::format("{}: no snapshot with atoms ('ITEM: ATOMS ...' rows) found; is this a LAMMPS or "
                                 "LIGGGHTS text dump?",
                                 rows.path()));
  last.header = {{"format", "lammps-dump"}, {"snapshots", snapshots}, {"timestep", timestep}};
  if (periodic[0] || periodic[1] || periodic[2]) {
    // A periodic box is the bed's container: a box with walls on its non-periodic sides, its
    // frame bedforge's (centred in x and y, z from the lower bound), and an axial period when z
    // is periodic.
    if (triclinic)
      throw InputError(fmt::format("{}: a periodic triclinic box; allowed: an orthogonal box ('ITEM: BOX BOUNDS pp "
                                   "pp pp')",
                                   rows.path()));
    const Eigen::Vector3d size = (box.col(1) - box.col(0)) * to_metres;
    const Eigen::Vector3d shift(0.5 * (box(0, 0) + box(0, 1)), 0.5 * (box(1, 0) + box(1, 1)), box(2, 0));
    for (auto& c : last.bed.centres) c -= shift * to_metres;
    auto container = std::make_shared<Box>(size.x(), size.y(), periodic[0], periodic[1]);
    if (periodic[2]) container->set_axial_period(size.z());
    last.bed.container = container;
    last.header["periodic"] = {periodic[0], periodic[1], periodic[2]};
  }
  return last;
}

ImportedBed read_yade_text(const std::filesystem::path& path, double to_metres) {
  const Lines lines(path);
  const RowReader rows(path);
  ImportedBed out;
  std::string format = "x_y_z_r";
  for (std::size_t i = 0; i < lines.text.size(); ++i) {
    const auto w = split_words(lines.text[i]);
    if (w.empty()) continue;
    if (w[0] == "#format") {
      format = w.size() > 1 ? w[1] : "";
      if (format != "x_y_z_r" && format != "x_y_z_r_matId" && format != "x_y_z_r_attrs" && format != "id_x_y_z_r_matId")
        throw InputError(fmt::format("{}:{}: #format {}; allowed: x_y_z_r, x_y_z_r_matId, x_y_z_r_attrs, "
                                     "id_x_y_z_r_matId",
                                     rows.path(), i + 1, format));
      continue;
    }
    if (w[0][0] == '#') continue;
    const std::size_t first = format == "id_x_y_z_r_matId" ? 1 : 0;
    const Eigen::Vector3d c(rows.number(w, first, i + 1, "x"), rows.number(w, first + 1, i + 1, "y"),
                            rows.number(w, first + 2, i + 1, "z"));
    rows.add_sphere(out, c, 2.0 * rows.number(w, first + 3, i + 1, "r"), i + 1, to_metres);
  }
  if (out.bed.size() == 0) throw InputError(fmt::format("{}: no sphere rows 'x y z r' found", rows.path()));
  out.header = {{"format", "yade"}, {"yade_format", format}};
  return out;
}

ImportedBed read_bed_file(const std::filesystem::path& path, BedFileFormat format, double to_metres,
                          const Eigen::Vector3d& origin_m) {
  ImportedBed in = format == BedFileFormat::lammps_dump ? read_lammps_dump(path, to_metres)
                   : format == BedFileFormat::yade      ? read_yade_text(path, to_metres)
                                                        : read_bed_text(path, to_metres);
  for (auto& c : in.bed.centres) c -= origin_m;
  return in;
}

}  // namespace bedforge
