#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/bed.hpp"

namespace bedforge {

// What made an output: recorded in the header of every file bedforge writes.
struct Provenance {
  std::string version;
  std::optional<unsigned long long> seed;
  nlohmann::json scene;  // the scene as run, after command-line overrides
};

// Bed as CSV: '#' header lines (format, version, seed, container, an empty bed's reference
// diameter, scene), then `x_m,y_m,z_m,d_m`
// and one sphere per line with 17 significant digits, so reading it back gives the same doubles.
std::string bed_to_csv(const Bed& bed, const Provenance& p);

// Bed as VTK XML PolyData (.vtp): one vertex per sphere with `diameter` and `radius` point data,
// for ParaView's Glyph filter (sphere glyph, scale by `diameter`, scale factor 1).
std::string bed_to_vtp(const Bed& bed, const Provenance& p);

// Reads sphere rows `x y z d` separated by commas, semicolons, tabs or spaces. Lines starting
// with '#' and a non-numeric first line (a column header) are skipped; `# container_m: {...}` in
// a bedforge header restores the container (and `# reference_diameter_m:` an empty bed, the one
// file allowed no rows). Every length is multiplied by `to_metres`
// (1 for metres, 1e-3 for millimetres). InputError names the file, line and field of a bad row.
struct ImportedBed {
  Bed bed;                   // container null unless the file recorded one
  nlohmann::json header;     // {"version", "seed", "scene"} when the file has a bedforge header
};
ImportedBed read_bed_text(const std::filesystem::path& path, double to_metres);

}  // namespace bedforge
