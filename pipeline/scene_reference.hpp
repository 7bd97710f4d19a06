#pragma once
#include <map>
#include <string>
#include <utility>

#include "core/scene_section.hpp"

namespace bedforge::pipeline {

// What a scene key means, in words: the one part of the scene reference the readers' schema
// (scene_schema: type, allowed values, default) cannot say.
struct KeyMeaning {
  KeyMeaning(std::string meaning, std::string unit = "", std::string why = "")
      : meaning(std::move(meaning)), unit(std::move(unit)), why(std::move(why)) {}
  std::string meaning;  // one or a few sentences; never a default (the schema has those)
  std::string unit;     // "" when the key's suffix says it (_d, _m, _deg, ...); "1" for a ratio
  std::string why;      // a heading of docs/defaults.md arguing its default, or ""
};

// Every scene key's meaning, by full dotted key ("surface.edge_length_d").
const std::map<std::string, KeyMeaning>& scene_key_meanings();

// The unit of `key`: its meaning's, else the one its suffix names, else "".
std::string key_unit(const std::string& key);

// GitHub's anchor of a Markdown heading: lower case, punctuation dropped, spaces to hyphens.
std::string heading_anchor(const std::string& heading);

// The scene reference as Markdown, one table per section, one row per key of `schema`: type,
// unit, default, allowed values and meaning, linked to docs/defaults.md where a default is
// argued there. docs/scene_reference.md is this text under its generated stamp (`bedforge
// scene-keys`); a key without a meaning is an std::logic_error, so the reference never skips one.
std::string scene_reference_markdown(const SceneSchema& schema);

// docs/scene_reference.md: its title, a stamp naming the bedforge `version` and the `date`
// (YYYY-MM-DD) that made it, then scene_reference_markdown(scene_schema()).
std::string scene_reference_page(const std::string& version, const std::string& date);

}  // namespace bedforge::pipeline
