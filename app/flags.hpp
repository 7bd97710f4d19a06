#pragma once
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "pipeline/scene.hpp"

namespace bedforge {

// The subcommands a scene option can act on.
enum class Command : unsigned { run = 1, pack = 2, import = 4, analyse = 8, surface = 16, mesh = 32, case_ = 64 };

// The command line's scene options: one table of {flag, scene keys, what it is, the commands it
// acts on} (flags.cpp). Each option's type, range and default are those the scene readers
// record (pipeline::scene_schema), so the help restates none by hand.
class SceneFlags {
 public:
  SceneFlags();
  // Adds the table's options that act on `command` to it, with their generated help.
  void add_to(CLI::App& app, Command command);
  // The options given, in table order, typed as their keys are; InputError naming the flag, the
  // value and what is allowed when a value is not of its key's type.
  std::vector<pipeline::Override> overrides() const;

 private:
  SceneSchema schema_;
  std::vector<std::vector<std::string>> given_;  // per table row: the values given (a flag: {"true"})
};

}  // namespace bedforge
