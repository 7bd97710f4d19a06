#include "core/scene_section.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "core/error.hpp"

namespace bedforge {

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (min_open ? !(v > min) : !(v >= min)) return false;
  if (max_open ? !(v < max) : !(v <= max)) return false;
  return true;
}

std::string Range::describe() const {
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  if (has_min && has_max)
    return fmt::format("a number in {}{}, {}{}", min_open ? "(" : "[", min, max, max_open ? ")" : "]");
  if (has_min) return fmt::format("a number {} {}", min_open ? ">" : ">=", min);
  if (has_max) return fmt::format("a number {} {}", max_open ? "<" : "<=", max);
  return "a finite number";
}

namespace {

std::string show(const toml::node& node) {
  std::ostringstream s;
  if (auto v = node.as_string()) s << '"' << v->get() << '"';
  else if (auto d = node.as_floating_point()) s << fmt::format("{}", d->get());
  else if (auto i = node.as_integer()) s << i->get();
  else if (auto b = node.as_boolean()) s << (b->get() ? "true" : "false");
  else if (node.is_table()) s << "a table";
  else if (node.is_array()) s << "an array";
  else s << "a value of another type";
  return s.str();
}

std::optional<double> as_number(const toml::node& node) {
  if (auto d = node.as_floating_point()) return d->get();
  if (auto i = node.as_integer()) return static_cast<double>(i->get());
  return std::nullopt;
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + ("\"" + v[i] + "\"");
  return out;
}

}  // namespace

SceneSection::SceneSection(const toml::table* table, std::string name, SceneSchema* schema)
    : table_(table), name_(std::move(name)), schema_(schema) {}

void SceneSection::record(const std::string& key, KeySpec spec) const {
  if (schema_) schema_->try_emplace(key_path(key), std::move(spec));
}

bool SceneSection::has(const std::string& key) const { return table_ && table_->contains(key); }

const toml::node* SceneSection::get(const std::string& key) {
  used_.insert(key);
  return table_ ? table_->get(key) : nullptr;
}

void SceneSection::fail(const std::string& key, const std::string& found, const std::string& allowed) const {
  throw InputError(fmt::format("{}: got {}; allowed: {}", key_path(key), found, allowed));
}

double SceneSection::number(const std::string& key, double fallback, Range range, const std::string& fallback_text) {
  return optional_number(key, range, fallback_text.empty() ? fmt::format("{}", fallback) : fallback_text)
      .value_or(fallback);
}

std::optional<double> SceneSection::optional_number(const std::string& key, Range range,
                                                    const std::string& fallback_text) {
  record(key, {"FLOAT", range.describe(), fallback_text});
  const toml::node* node = get(key);
  if (!node) return std::nullopt;
  auto v = as_number(*node);
  if (!v) fail(key, show(*node), range.describe());
  if (!range.contains(*v)) fail(key, show(*node), range.describe());
  return v;
}

long long SceneSection::integer(const std::string& key, long long fallback, long long min, long long max,
                                const std::string& fallback_text) {
  const std::string allowed = fmt::format("an integer in [{}, {}]", min, max);
  record(key, {"INT", allowed, fallback_text.empty() ? std::to_string(fallback) : fallback_text});
  const toml::node* node = get(key);
  if (!node) return fallback;
  auto i = node->as_integer();
  if (!i) fail(key, show(*node), allowed);
  if (i->get() < min || i->get() > max) fail(key, show(*node), allowed);
  return i->get();
}

bool SceneSection::boolean(const std::string& key, bool fallback) {
  record(key, {"BOOL", "true or false", fallback ? "true" : "false"});
  const toml::node* node = get(key);
  if (!node) return fallback;
  auto b = node->as_boolean();
  if (!b) fail(key, show(*node), "true or false");
  return b->get();
}

std::string SceneSection::choice(const std::string& key, const std::string& fallback,
                                 const std::vector<std::string>& allowed) {
  record(key, {"STRING", "one of " + join(allowed), fallback});
  const toml::node* node = get(key);
  if (!node) return fallback;
  auto s = node->as_string();
  if (!s) fail(key, show(*node), "one of " + join(allowed));
  for (const auto& a : allowed)
    if (a == s->get()) return a;
  fail(key, show(*node), "one of " + join(allowed));
}

std::vector<double> SceneSection::numbers(const std::string& key, Range range) {
  record(key, {"FLOAT...", "numbers, each " + range.describe(), "none"});
  const toml::node* node = get(key);
  if (!node) return {};
  auto arr = node->as_array();
  const std::string allowed = "an array of numbers, each " + range.describe();
  if (!arr || arr->empty()) fail(key, show(*node), "a non-empty " + allowed.substr(3));
  std::vector<double> out;
  for (size_t i = 0; i < arr->size(); ++i) {
    auto v = as_number(*arr->get(i));
    if (!v || !range.contains(*v)) fail(fmt::format("{}[{}]", key, i), show(*arr->get(i)), range.describe());
    out.push_back(*v);
  }
  return out;
}

std::vector<std::string> SceneSection::strings(const std::string& key, const std::vector<std::string>& fallback,
                                               const std::vector<std::string>& allowed) {
  std::string fallback_text;
  for (const auto& f : fallback) fallback_text += (fallback_text.empty() ? "" : " ") + f;
  record(key, {"STRING...", "any of " + join(allowed), fallback_text});
  const toml::node* node = get(key);
  if (!node) return fallback;
  auto arr = node->as_array();
  if (!arr) fail(key, show(*node), "an array of strings from " + join(allowed));
  std::vector<std::string> out;
  for (size_t i = 0; i < arr->size(); ++i) {
    auto s = arr->get(i)->as_string();
    bool ok = s != nullptr;
    if (ok) {
      ok = false;
      for (const auto& a : allowed) ok = ok || a == s->get();
    }
    if (!ok) fail(fmt::format("{}[{}]", key, i), show(*arr->get(i)), "one of " + join(allowed));
    out.push_back(s->get());
  }
  return out;
}

std::optional<std::string> SceneSection::optional_string(const std::string& key) {
  record(key, {"STRING", "a string", "none"});
  const toml::node* node = get(key);
  if (!node) return std::nullopt;
  auto s = node->as_string();
  if (!s) fail(key, show(*node), "a string");
  return s->get();
}

std::optional<Length> SceneSection::optional_length(const std::string& name, Range range,
                                                   const std::optional<Length>& fallback) {
  const bool in_m = has(name + "_m"), in_d = has(name + "_d");
  if (in_m && in_d)
    throw InputError(fmt::format("{0}_m and {0}_d are both given; give the length once, in metres (_m) or in "
                                 "particle diameters (_d)",
                                 key_path(name)));
  auto fallback_in = [&](Length::Unit unit) {
    if (!fallback) return std::string("none");
    return fallback->unit == unit ? fmt::format("{}", fallback->value)
                                  : fmt::format("none ({}_{} is)", name, unit == Length::Unit::metres ? "d" : "m");
  };
  auto m = optional_number(name + "_m", range, fallback_in(Length::Unit::metres));
  auto d = optional_number(name + "_d", range, fallback_in(Length::Unit::diameters));
  if (m) return Length{*m, Length::Unit::metres};
  if (d) return Length{*d, Length::Unit::diameters};
  return std::nullopt;
}

Length SceneSection::length(const std::string& name, Length fallback, Range range) {
  return optional_length(name, range, fallback).value_or(fallback);
}

SceneSection SceneSection::sub(const std::string& key) {
  const toml::node* node = get(key);
  if (node && !node->is_table()) fail(key, show(*node), "a table");
  return SceneSection(node ? node->as_table() : nullptr, key_path(key), schema_);
}

void SceneSection::finish() const {
  if (!table_) return;
  for (const auto& [k, v] : *table_) {
    const std::string key(k.str());
    if (!used_.count(key)) {
      std::vector<std::string> known(used_.begin(), used_.end());
      throw InputError(fmt::format("unknown key '{}'; allowed keys in [{}]: {}", key_path(key), name_, join(known)));
    }
  }
}

toml::table parse_scene_text(const std::string& text, const std::string& source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: TOML syntax error: {}", source_name, e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}

}  // namespace bedforge
