#pragma once
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace bedforge {

// Writes `contents` to `path` through a temporary file in the same directory and a rename, so a
// reader never sees a half-written file and a failed run leaves the previous file intact.
// Creates missing parent directories. Throws InputError when the directory cannot be written.
void write_file_atomically(const std::filesystem::path& path, const std::string& contents);
// The same, with the contents streamed by `write` (large files never held in memory whole).
void write_file_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

// A directory built whole by `write` (given a temporary sibling of `dir` to fill), then put in
// place of `dir` (any old one removed only then); on any exception the temporary directory is
// removed and the exception goes on. So no half-written directory is ever left at `dir`.
void write_directory_atomically(const std::filesystem::path& dir,
                                const std::function<void(const std::filesystem::path&)>& write);

// Whole file as a string; InputError naming the path when it cannot be read.
std::string read_file(const std::filesystem::path& path);

}  // namespace bedforge
