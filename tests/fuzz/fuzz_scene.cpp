// libFuzzer target: scene text through the TOML parser and the scene reader. Any input must end
// in a scene or an InputError that names what is wrong; a crash, a sanitizer report, a hang or
// another exception is a finding. Run: build-fuzz/tests/fuzz/fuzz_scene CORPUS tests/fuzz/seeds/scenes
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "pipeline/scene.hpp"
#include "core/error.hpp"
#include "core/scene_section.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // Relative packing.file names resolve into an empty folder: imports fail by name.
    bedforge::pipeline::read_scene(bedforge::parse_scene_text(text, "fuzz.toml"), "fuzz.toml",
                         std::filesystem::temp_directory_path() / "bedforge_fuzz_empty");
  } catch (const bedforge::InputError&) {
  }
  return 0;
}
