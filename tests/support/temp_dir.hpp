#pragma once
// Scratch directories for tests: all under one directory per test process, removed when the
// process ends, so repeated runs leave nothing behind in the system's temporary directory.
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace test_support {

inline const std::filesystem::path& process_temp_dir() {
  static const struct Owned {
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("bedforge_test_" + std::to_string(::getpid()));
    ~Owned() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  } dir;
  return dir.path;
}

// `name` under the process's directory, emptied; created when `create` is set.
inline std::filesystem::path fresh_dir(const std::string& name, bool create = false) {
  const auto d = process_temp_dir() / name;
  std::filesystem::remove_all(d);
  if (create) std::filesystem::create_directories(d);
  return d;
}

}  // namespace test_support
