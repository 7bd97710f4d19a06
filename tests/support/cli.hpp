#pragma once
// Running the bedforge program from a test, as a user does: BEDFORGE_BINARY and
// BEDFORGE_SOURCE_DIR come from tests/CMakeLists.txt.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/temp_dir.hpp"

namespace cli_test {

struct Result {
  int status;
  std::string output;  // stdout and stderr
};

// `command` run from the source directory (so scenes/... paths work); BEDFORGE_BINARY replaces
// a leading "bedforge".
inline Result shell(const std::string& command) {
  const std::string cmd = std::string("cd ") + BEDFORGE_SOURCE_DIR + " && " + command + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

inline Result bedforge(const std::string& args) { return shell(std::string(BEDFORGE_BINARY) + " " + args); }

// An empty path under the test process's temporary directory.
inline std::filesystem::path fresh_dir(const std::string& name) { return test_support::fresh_dir(name); }

inline std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace cli_test
