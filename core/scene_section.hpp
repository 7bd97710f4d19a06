#pragma once
#include <toml++/toml.h>

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace bedforge {

// Allowed interval for a number read from a scene; `describe()` is what an error message shows.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  // true: min itself is not allowed
  bool max_open = false;
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range open(double lo, double hi) { return {lo, hi, true, true}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  bool contains(double v) const;
  std::string describe() const;
};

// A length given in a scene either in metres (`<name>_m`) or in particle diameters (`<name>_d`).
struct Length {
  enum class Unit { metres, diameters };
  double value = 0.0;
  Unit unit = Unit::diameters;
  double metres(double d_ref_m) const { return unit == Unit::metres ? value : value * d_ref_m; }
  double diameters(double d_ref_m) const { return unit == Unit::diameters ? value : value / d_ref_m; }
};

// What a scene key takes, as its reader asks for it; the command line's help is generated from
// these, so no range or default is restated by hand.
struct KeySpec {
  std::string type;      // "FLOAT", "INT", "BOOL", "STRING", "FLOAT..." (an array), "STRING..."
  std::string allowed;   // e.g. "a number in (0, 1)" or "one of \"hxt\", \"delaunay\""
  std::string fallback;  // the default as text; "none" where absence means none
};
using SceneSchema = std::map<std::string, KeySpec>;  // full dotted key -> spec

// Typed, checked access to one table of a scene (`[packing]`, ...). Every getter throws
// InputError naming the full key, the value found and what is allowed; `finish()` rejects keys
// that no getter asked for, so a misspelt key never passes silently.
class SceneSection {
 public:
  // `table` may be null (section absent): every getter then returns its default. With `schema`,
  // every key asked for (here and in sub-sections) is recorded there with its type, range and
  // default.
  SceneSection(const toml::table* table, std::string name, SceneSchema* schema = nullptr);

  const std::string& name() const { return name_; }
  bool has(const std::string& key) const;
  std::string key_path(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }

  // `fallback_text`, where given, is what help shows as the default (a default computed later).
  double number(const std::string& key, double fallback, Range range, const std::string& fallback_text = {});
  std::optional<double> optional_number(const std::string& key, Range range, const std::string& fallback_text = "none");
  long long integer(const std::string& key, long long fallback, long long min, long long max,
                    const std::string& fallback_text = {});
  bool boolean(const std::string& key, bool fallback);
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed);
  std::vector<double> numbers(const std::string& key, Range range);  // empty when absent
  std::vector<std::string> strings(const std::string& key, const std::vector<std::string>& fallback,
                                   const std::vector<std::string>& allowed);
  std::optional<std::string> optional_string(const std::string& key);
  // Reads `<name>_m` or `<name>_d` (exactly one may be present).
  std::optional<Length> optional_length(const std::string& name, Range range,
                                        const std::optional<Length>& fallback = std::nullopt);
  Length length(const std::string& name, Length fallback, Range range);
  // A nested table (e.g. `[packing.faithful]`), checked the same way.
  SceneSection sub(const std::string& key);

  void finish() const;

 private:
  const toml::node* get(const std::string& key);
  void record(const std::string& key, KeySpec spec) const;
  [[noreturn]] void fail(const std::string& key, const std::string& found, const std::string& allowed) const;

  const toml::table* table_;
  std::string name_;
  std::set<std::string> used_;
  SceneSchema* schema_;
};

// Parses TOML text; InputError with the file name, line and column on a syntax error.
toml::table parse_scene_text(const std::string& text, const std::string& source_name);

}  // namespace bedforge
