#include "core/scene_section.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"
#include "support/input_error.hpp"

using namespace bedforge;
using input_error_test::error_of;

namespace {

toml::table parse(const char* text) { return parse_scene_text(text, "test.toml"); }


}  // namespace

TEST(SceneSection, ReadsTypedValuesAndDefaults) {
  const auto t = parse("[packing]\nseed = 7\nstep = 0.25\nmode = \"faithful\"\n");
  SceneSection s(t["packing"].as_table(), "packing");
  EXPECT_EQ(s.integer("seed", 1, 0, 100), 7);
  EXPECT_DOUBLE_EQ(s.number("step", 1.0, Range::positive()), 0.25);
  EXPECT_DOUBLE_EQ(s.number("absent", 3.5, Range::positive()), 3.5);
  EXPECT_EQ(s.choice("mode", "accelerated", {"accelerated", "faithful"}), "faithful");
  EXPECT_NO_THROW(s.finish());
}

TEST(SceneSection, IntegersAreAcceptedWhereNumbersAreAsked) {
  const auto t = parse("[c]\ndiameter_d = 5\n");
  SceneSection s(t["c"].as_table(), "c");
  EXPECT_DOUBLE_EQ(s.number("diameter_d", 0.0, Range::positive()), 5.0);
}

TEST(SceneSection, OutOfRangeNamesKeyValueAndAllowed) {
  const auto t = parse("[particles]\ncount = 0\nstep = -1.5\n");
  SceneSection s(t["particles"].as_table(), "particles");
  const std::string count = error_of([&] { s.integer("count", 1, 1, 1000); });
  EXPECT_NE(count.find("particles.count"), std::string::npos) << count;
  EXPECT_NE(count.find("got 0"), std::string::npos) << count;
  EXPECT_NE(count.find("[1, 1000]"), std::string::npos) << count;
  const std::string step = error_of([&] { s.number("step", 1.0, Range::positive()); });
  EXPECT_NE(step.find("particles.step: got -1.5; allowed: a number > 0"), std::string::npos) << step;
}

TEST(SceneSection, NanAndInfinityAreRejected) {
  const auto t = parse("[a]\nx = nan\ny = inf\n");
  SceneSection s(t["a"].as_table(), "a");
  EXPECT_NE(error_of([&] { s.number("x", 1.0, Range{}); }).find("a.x"), std::string::npos);
  EXPECT_NE(error_of([&] { s.number("y", 1.0, Range::positive()); }).find("a.y"), std::string::npos);
}

TEST(SceneSection, WrongTypeIsAnError) {
  const auto t = parse("[a]\nx = \"five\"\nn = 2.5\nflag = 1\n");
  SceneSection s(t["a"].as_table(), "a");
  EXPECT_NE(error_of([&] { s.number("x", 1.0, Range{}); }).find("got \"five\""), std::string::npos);
  EXPECT_NE(error_of([&] { s.integer("n", 1, 0, 10); }).find("an integer"), std::string::npos);
  EXPECT_NE(error_of([&] { s.boolean("flag", false); }).find("true or false"), std::string::npos);
}

TEST(SceneSection, UnknownKeyIsNamedWithTheAllowedOnes) {
  const auto t = parse("[packing]\nseed = 1\nsead = 2\n");
  SceneSection s(t["packing"].as_table(), "packing");
  s.integer("seed", 1, 0, 10);
  const std::string e = error_of([&] { s.finish(); });
  EXPECT_NE(e.find("unknown key 'packing.sead'"), std::string::npos) << e;
  EXPECT_NE(e.find("\"seed\""), std::string::npos) << e;
}

TEST(SceneSection, LengthInEitherUnitButNotBoth) {
  const auto t = parse("[a]\nd_m = 0.5\n[b]\nd_d = 2.0\n[c]\nd_m = 1.0\nd_d = 1.0\n");
  SceneSection a(t["a"].as_table(), "a"), b(t["b"].as_table(), "b"), c(t["c"].as_table(), "c");
  const Length la = *a.optional_length("d", Range::positive());
  const Length lb = *b.optional_length("d", Range::positive());
  EXPECT_DOUBLE_EQ(la.metres(0.1), 0.5);
  EXPECT_DOUBLE_EQ(la.diameters(0.1), 5.0);
  EXPECT_DOUBLE_EQ(lb.metres(0.1), 0.2);
  EXPECT_NE(error_of([&] { c.optional_length("d", Range::positive()); }).find("both given"), std::string::npos);
}

TEST(SceneSection, SyntaxErrorNamesFileAndLine) {
  const std::string e = error_of([] { parse("[a]\nx = = 1\n"); });
  EXPECT_NE(e.find("test.toml:2"), std::string::npos) << e;
}

TEST(SceneSection, ArraysAreCheckedElementByElement) {
  const auto t = parse("[p]\nd = [0.1, -0.2]\nempty = []\n");
  SceneSection s(t["p"].as_table(), "p");
  EXPECT_NE(error_of([&] { s.numbers("d", Range::positive()); }).find("p.d[1]: got -0.2"), std::string::npos);
  EXPECT_NE(error_of([&] { s.numbers("empty", Range::positive()); }).find("p.empty"), std::string::npos);
}
