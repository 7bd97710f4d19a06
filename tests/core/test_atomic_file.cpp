#include "core/atomic_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/error.hpp"
#include "support/temp_dir.hpp"

using namespace bedforge;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  const fs::path d = test_support::process_temp_dir() / "atomic_file";
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(AtomicFile, LeavesNoTemporaryBehind) {
  const fs::path d = temp_dir() / "atomic";
  write_file_atomically(d / "a.txt", "one");
  write_file_atomically(d / "a.txt", "two");
  EXPECT_EQ(read_file(d / "a.txt"), "two");
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++files;
  EXPECT_EQ(files, 1);
}

TEST(AtomicFile, UnwritableDirectoryIsAnInputError) {
  EXPECT_THROW(write_file_atomically("/proc/bedforge/x.txt", "x"), InputError);
  EXPECT_THROW(read_file(temp_dir() / "absent.txt"), InputError);
}
