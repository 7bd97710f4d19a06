// libFuzzer target: the bed importers (xyzd text, LAMMPS/LIGGGHTS dump, Yade text). The first
// byte picks the format, the rest is the file. Any input must give a bed or an InputError naming
// the line; a crash, a sanitizer report, a hang or another exception is a finding.
// Run: build-fuzz/tests/fuzz/fuzz_bed_import CORPUS tests/fuzz/seeds/bed_import
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "core/dem_import.hpp"
#include "core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const struct Scratch {  // one file per fuzzing process, removed when it ends
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("bedforge_fuzz_bed_" + std::to_string(::getpid()));
    ~Scratch() {
      std::error_code ignored;
      std::filesystem::remove(path, ignored);
    }
  } scratch;
  const std::filesystem::path& file = scratch.path;
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  const bedforge::BedFileFormat format = data[0] % 3 == 0   ? bedforge::BedFileFormat::xyzd
                                         : data[0] % 3 == 1 ? bedforge::BedFileFormat::lammps_dump
                                                            : bedforge::BedFileFormat::yade;
  try {
    const bedforge::ImportedBed in = bedforge::read_bed_file(file, format, 1e-3);
    // What an importer returns must be a usable bed: finite centres, positive finite diameters.
    for (std::size_t i = 0; i < in.bed.size(); ++i)
      if (!in.bed.centres[i].allFinite() || !(in.bed.diameters[i] > 0.0) || !std::isfinite(in.bed.diameters[i]))
        std::abort();
  } catch (const bedforge::InputError&) {
  }
  return 0;
}
