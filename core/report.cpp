#include "core/report.hpp"

#include <fmt/format.h>

#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace bedforge {

Report Report::load_or_new(const std::filesystem::path& dir) {
  Report r;
  const auto path = dir / "report.json";
  if (std::filesystem::exists(path)) {
    try {
      r.data_ = nlohmann::json::parse(read_file(path));
    } catch (const nlohmann::json::exception& e) {
      throw InputError(fmt::format("{}: not a readable report ({}); remove it or choose another directory",
                                   path.string(), e.what()));
    }
  }
  return r;
}

void Report::set_provenance(const std::string& version, const nlohmann::json& scene, unsigned long long seed) {
  data_["bedforge_version"] = version;
  data_["scene"] = scene;
  data_["seed"] = seed;
}

void Report::set_stage(const std::string& name, nlohmann::json stage) {
  data_["stages"][name] = std::move(stage);
  nlohmann::json summary = nlohmann::json::object();
  for (const auto& [k, v] : data_["stages"].items()) summary[k] = v.value("summary", "");
  data_["summary"] = summary;
}

void Report::save(const std::filesystem::path& dir) const {
  write_file_atomically(dir / "report.json", data_.dump(2) + "\n");
}

}  // namespace bedforge
