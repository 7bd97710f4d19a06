#pragma once
#include <toml++/toml.h>

#include <limits>
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

// Typed, checked access to one table of a scene (`[packing]`, ...). Every getter throws
// InputError naming the full key, the value found and what is allowed; `finish()` rejects keys
// that no getter asked for, so a misspelt key never passes silently.
class SceneSection {
 public:
  // `table` may be null (section absent): every getter then returns its default.
  SceneSection(const toml::table* table, std::string name);

  const std::string& name() const { return name_; }
  bool has(const std::string& key) const;
  std::string key_path(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }

  double number(const std::string& key, double fallback, Range range);
  std::optional<double> optional_number(const std::string& key, Range range);
  long long integer(const std::string& key, long long fallback, long long min, long long max);
  bool boolean(const std::string& key, bool fallback);
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed);
  std::vector<double> numbers(const std::string& key, Range range);  // empty when absent
  std::vector<std::string> strings(const std::string& key, const std::vector<std::string>& fallback,
                                   const std::vector<std::string>& allowed);
  std::optional<std::string> optional_string(const std::string& key);
  // Reads `<name>_m` or `<name>_d` (exactly one may be present).
  std::optional<Length> optional_length(const std::string& name, Range range);
  Length length(const std::string& name, Length fallback, Range range);
  // A nested table (e.g. `[packing.faithful]`), checked the same way.
  SceneSection sub(const std::string& key);

  void finish() const;

 private:
  const toml::node* get(const std::string& key);
  [[noreturn]] void fail(const std::string& key, const std::string& found, const std::string& allowed) const;

  const toml::table* table_;
  std::string name_;
  std::set<std::string> used_;
};

// Parses TOML text; InputError with the file name, line and column on a syntax error.
toml::table parse_scene_text(const std::string& text, const std::string& source_name);

}  // namespace bedforge
