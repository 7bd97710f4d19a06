#include "core/report.hpp"

#include <fmt/format.h>

#include <cstdint>

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
  std::string text = fmt::format("bedforge {}, seed {}\n", data_.value("bedforge_version", std::string("?")),
                                 data_.contains("seed") ? data_["seed"].dump() : std::string("none"));
  if (data_.contains("stages"))
    for (const char* stage : {"pack", "analysis", "surface", "mesh", "case"})  // pipeline order
      if (data_["stages"].contains(stage)) text += data_["stages"][stage].value("summary", std::string()) + "\n";
  // The run's answer, when its case was solved, last.
  const nlohmann::json none = nlohmann::json::object(), &stages = data_.contains("stages") ? data_["stages"] : none;
  for (const auto& line : stages.value("case", none).value("answer", none).value("lines", nlohmann::json::array()))
    text += line.get<std::string>() + "\n";
  write_file_atomically(dir / "summary.txt", text);
}

std::string stage_key(const nlohmann::json& inputs) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : inputs.dump()) h = (h ^ c) * 0x100000001b3ULL;
  return fmt::format("{:016x}", h);
}

nlohmann::json thin_history(const nlohmann::json& history, std::size_t max_points) {
  nlohmann::json h = nlohmann::json::array();
  const std::size_t n = history.size(), stride = n > max_points ? (n + max_points - 1) / max_points : 1;
  for (std::size_t i = 0; i < n; ++i)
    if (i % stride == 0 || i + 1 == n) h.push_back(history[i]);
  return h;
}

}  // namespace bedforge
