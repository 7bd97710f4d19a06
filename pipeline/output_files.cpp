#include "pipeline/output_files.hpp"

#include <memory>

#include "core/atomic_file.hpp"

namespace bedforge::pipeline {

namespace fs = std::filesystem;

OutputFiles::~OutputFiles() {
  std::error_code ec;
  for (const auto& m : made_) fs::remove(m.second, ec);
}

void OutputFiles::add(std::string name, std::string contents) {
  auto text = std::make_shared<const std::string>(std::move(contents));
  add_writer(std::move(name), [text](std::ostream& out) { out << *text; });
}

void OutputFiles::add_writer(std::string name, Writer write) { files_.emplace_back(std::move(name), std::move(write)); }

void OutputFiles::add_made(std::string name, fs::path temporary) {
  made_.emplace_back(std::move(name), std::move(temporary));
}

void OutputFiles::write(const fs::path& dir) {
  for (const auto& [name, writer] : files_) write_file_atomically(dir / name, writer);
  for (const auto& [name, temporary] : made_) fs::rename(temporary, dir / name);
  files_.clear();
  made_.clear();
}

}  // namespace bedforge::pipeline
