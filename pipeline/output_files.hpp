#pragma once
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace bedforge::pipeline {

// The files of one run, written together at the end so a failure leaves nothing half-made.
// Large files are streamed by a writer at that point instead of held as a string.
class OutputFiles {
 public:
  using Writer = std::function<void(std::ostream&)>;
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();  // removes the files made by a library that were never renamed

  void add(std::string name, std::string contents);
  void add_writer(std::string name, Writer write);
  // A file a library wrote itself (gmsh) at `temporary`, renamed to `name` with the others.
  void add_made(std::string name, std::filesystem::path temporary);
  // Writes every file into `dir` (each through a temporary name and a rename), then forgets them.
  void write(const std::filesystem::path& dir);

 private:
  std::vector<std::pair<std::string, Writer>> files_;
  std::vector<std::pair<std::string, std::filesystem::path>> made_;
};

}  // namespace bedforge::pipeline
