// The command line's scene options: help generated from the scene readers, values typed by the
// keys they set.
#include "app/flags.hpp"

#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"

using namespace bedforge;

namespace {

std::string help_of(Command command) {
  CLI::App app;
  SceneFlags flags;
  flags.add_to(app, command);
  return app.help();
}

std::vector<pipeline::Override> parse(Command command, std::vector<std::string> args) {
  CLI::App app;
  SceneFlags flags;
  flags.add_to(app, command);
  std::reverse(args.begin(), args.end());  // CLI11 takes the arguments in reverse order
  app.parse(args);
  return flags.overrides();
}

}  // namespace

TEST(Flags, HelpStatesRangeKeyAndDefaultFromTheSceneReaders) {
  const std::string pack = help_of(Command::pack);
  // Defaults and ranges as the readers hold them, not restated in the table.
  EXPECT_NE(pack.find("a number in (0, 1); sets packing.soft_sphere.initial_void_fraction); default 0.47"),
            std::string::npos)
      << pack;
  EXPECT_NE(pack.find("sets packing.monte_carlo.shakes); default 10 for equal spheres, 100 for mixtures"),
            std::string::npos)
      << pack;
  EXPECT_NE(pack.find("sets particles.count); default none (required)"), std::string::npos) << pack;
  const std::string surface = help_of(Command::surface);
  EXPECT_NE(surface.find("--clip-window-d FLOAT x 2"), std::string::npos) << surface;  // the window's pair
  EXPECT_NE(surface.find("sets contacts.treatment); default bridge"), std::string::npos) << surface;
}

TEST(Flags, EachCommandOffersOnlyTheOptionsThatActOnIt) {
  const std::string import = help_of(Command::import);
  for (const char* packing_only : {"--temperature", "--shakes", "--mode", "--count", "--seed"})
    EXPECT_EQ(import.find(packing_only), std::string::npos) << packing_only;
  for (const char* own : {"--units", "--origin-m", "--aspect-ratio", "--container-diameter-m"})
    EXPECT_NE(import.find(own), std::string::npos) << own;
  EXPECT_EQ(help_of(Command::analyse).find("--contacts"), std::string::npos);
  EXPECT_EQ(help_of(Command::mesh).find("--reynolds"), std::string::npos);
}

TEST(Flags, ValuesAreTypedByTheirKeysAndBadOnesNamed) {
  const auto o = parse(Command::pack, {"--count", "40", "--aspect-ratio", "3.5", "--mode", "faithful", "--periodic"});
  ASSERT_EQ(o.size(), 5u);  // --periodic sets two keys
  auto value = [&](const std::string& key) {
    for (const auto& x : o)
      if (x.key == key) return x.value;
    ADD_FAILURE() << key;
    return pipeline::Override{}.value;
  };
  EXPECT_EQ(std::get<long long>(value("particles.count")), 40);
  EXPECT_EQ(std::get<double>(value("container.diameter_d")), 3.5);
  EXPECT_EQ(std::get<std::string>(value("packing.soft_sphere.mode")), "faithful");
  EXPECT_TRUE(std::get<bool>(value("container.periodic_y")));
  try {
    parse(Command::pack, {"--count", "forty"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--count"), std::string::npos) << m;
    EXPECT_NE(m.find("particles.count"), std::string::npos) << m;
    EXPECT_NE(m.find("'forty'"), std::string::npos) << m;
  }
  const auto window = parse(Command::surface, {"--clip-window-d", "1", "3"});
  ASSERT_EQ(window.size(), 1u);
  EXPECT_EQ(std::get<std::vector<double>>(window[0].value), (std::vector<double>{1.0, 3.0}));
}
