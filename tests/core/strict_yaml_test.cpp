// SPDX-License-Identifier: MIT
// Tests of ConfigNode's strict YAML: duplicate keys, alias expansion, NUL bytes, invalid UTF-8,
// nesting depth and the file reading of load_file (docs/security.md, "Strict input files").
#include <doctest/doctest.h>

#include <string>

#include "llsf/core/config.h"
#include "llsf/core/error.h"
#include "support/temp_dir.h"

using llsf::core::ConfigError;
using llsf::core::ConfigNode;

namespace {

/// The message of the ConfigError that parsing `text` throws, or "" if it parses.
std::string parse_error(const std::string& text, const std::string& name = "d.yaml") {
  try {
    (void)ConfigNode::parse(text, name);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

/// A document whose aliases expand to 10^`levels` nodes ("billion laughs").
std::string laughs(int levels, const std::string& indent = "") {
  std::string text = indent + "l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int i = 1; i <= levels; ++i) {
    const std::string p = "*l" + std::to_string(i - 1);
    text += indent + "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [" + p;
    for (int k = 1; k < 10; ++k) text += ", " + p;
    text += "]\n";
  }
  return text;
}

/// `depth` flow lists inside each other under the key `a`.
std::string nested(int depth) {
  return "a: " + std::string(static_cast<std::size_t>(depth), '[') + "1" +
         std::string(static_cast<std::size_t>(depth), ']') + "\n";
}

}  // namespace

TEST_CASE("a key given twice in a map is refused at its second line") {
  CHECK(parse_error("a: 1\nb: 2\na: 3\n") ==
        "d.yaml:3:1: a: key 'a' given twice (first at line 1)");
  CHECK(parse_error("robots:\n  count: 2\n  locks: true\n  count: 3\n") ==
        "d.yaml:4:3: robots.count: key 'count' given twice (first at line 2)");
  CHECK(parse_error("tests:\n  - name: x\n  - name: y\n    by_s: 1\n    name: z\n") ==
        "d.yaml:5:5: tests[1].name: key 'name' given twice (first at line 3)");
  CHECK(parse_error("rates: {physics_hz: 60,\n  physics_hz: 30}\n") ==
        "d.yaml:2:3: rates.physics_hz: key 'physics_hz' given twice (first at line 1)");
  // Quoting does not make a different key.
  CHECK(parse_error("a: 1\n\"a\": 2\n") == "d.yaml:2:1: a: key 'a' given twice (first at line 1)");
  // The same key in different maps, and a map that repeats no key, are fine.
  CHECK(parse_error("a: {x: 1}\nb: {x: 1}\nc: [{x: 1}, {x: 2}]\n").empty());
}

TEST_CASE("aliases may not expand the document past a million nodes") {
  // Ten levels of ten: 10^10 nodes once expanded, a few hundred bytes of text.
  const std::string error = parse_error(laughs(9), "laughs.yaml");
  CHECK(error.rfind("laughs.yaml:", 0) == 0);
  CHECK(error.find("aliases expand the document to more than 1000000 nodes") != std::string::npos);
  // At the alias that crosses the limit: in l5 (10^6 nodes), after l0..l4 and 7 of its 10.
  CHECK(error.find("laughs.yaml:6:45: l5[7]: ") == 0);
  // Nested under a key of an agent's config, too.
  const std::string nested_error =
      parse_error("robots:\n  config:\n" + laughs(8, "    "), "agent.yaml");
  CHECK(nested_error.find("agent.yaml:") == 0);
  CHECK(nested_error.find("robots.config.l") != std::string::npos);
  // A few aliases are fine and read as their anchors.
  const ConfigNode ok = ConfigNode::parse(laughs(3), "ok.yaml");
  CHECK(ok["l3"].size() == 10);
  CHECK(ok["l3"].at(9).at(0).at(0).at(0).as_string() == "lol");
}

TEST_CASE("an alias inside its own anchor is refused") {
  const std::string error = parse_error("a: &x\n  b: *x\n", "r.yaml");
  CHECK(error.find("r.yaml:2:") == 0);
  CHECK(error.find("a.b: the alias *x is inside its own anchor") != std::string::npos);
}

TEST_CASE("NUL bytes and invalid UTF-8 are refused at their line and column") {
  CHECK(parse_error(std::string("a: 1\nname: r\0b\n", 13), "n.yaml") ==
        "n.yaml:2:8: a NUL byte: YAML must be text");
  CHECK(parse_error("a: 1\nname: r\xff"
                    "1\n",
                    "u.yaml") == "u.yaml:2:8: invalid UTF-8 (byte 0xFF): YAML must be UTF-8 text");
  // After characters of several bytes the column still counts characters.
  CHECK(parse_error("name: \xc3\xa4\xc3\xb6\xc0\xaf\n", "u.yaml") ==
        "u.yaml:1:9: invalid UTF-8 (byte 0xC0): YAML must be UTF-8 text");
  CHECK(parse_error("name: \xed\xa0\x80\n", "u.yaml").find("u.yaml:1:7: invalid UTF-8") == 0);
  CHECK(parse_error("name: Zo\xc3\xab \xe2\x82\xac \xf0\x9f\x98\x80\n").empty());
}

TEST_CASE("nesting deeper than 64 levels is refused with its own message") {
  // The top-level map and 63 lists: 64 levels.
  CHECK(parse_error(nested(63)).empty());
  // A long path is shortened in the middle.
  const std::string path =
      "a[0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][...0][0][0]"
      "[0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0]";
  CHECK(parse_error(nested(64)) ==
        "d.yaml:1:67: " + path +
            ": nesting deeper than 64 levels (maps and lists inside each other)");
  // yaml-cpp alone stops at 500 levels with "bad file"; 100,000 are refused as 64 are.
  const std::string deep = parse_error("a: " + std::string(100000, '[') + "\n");
  CHECK(deep.find("d.yaml:1:") == 0);
  CHECK(deep.find("nesting deeper than 64 levels") != std::string::npos);
  // Block maps count as well.
  std::string block;
  for (int i = 0; i < 70; ++i) block += std::string(static_cast<std::size_t>(i), ' ') + "k:\n";
  CHECK(parse_error(block).find("d.yaml:65:65: k.k.k.") == 0);
  CHECK(parse_error(block).find("nesting deeper than 64 levels") != std::string::npos);
}

TEST_CASE("load_file reads only regular files") {
  const llsf::test::TempDir dir;
  CHECK_THROWS_WITH_AS(ConfigNode::load_file(dir.path.string()),
                       (dir.path.string() + ": not a regular file (a directory); the YAML file "
                                            "must be one")
                           .c_str(),
                       ConfigError);
  CHECK_THROWS_WITH_AS(ConfigNode::load_file("/dev/null"),
                       "/dev/null: not a regular file (a character device); the YAML file must be "
                       "one",
                       ConfigError);
}

TEST_CASE("locate_errors with renames puts a struct's path on the document's key and line") {
  const ConfigNode root = ConfigNode::parse(
      "name: x\n"
      "rates:\n"
      "  physics_hz: 5\n"
      "  skill_hz: 15\n"
      "levels:\n"
      "  position_noise_m: -1\n"
      "robots:\n"
      "  each:\n"
      "    - {name: a}\n"
      "    - {name: a}\n"
      "world:\n"
      "  robots:\n"
      "    - {name: w, jersey: 100}\n",
      "d.yaml");
  static constexpr llsf::core::PathRename kRenames[] = {
      {"game.skill", "nothing"},  // a prefix only up to a '.' or '['
      {"game.skill_rate_hz", "rates.skill_hz"},
      {"game.levels.localization.position_noise_m", "levels.position_noise_m"},
      {"robots[", "robots.each["},
      {"robots[", "world.robots["},
      {"game", ""},
  };
  const auto error_of = [&](const std::string& message) {
    try {
      root.locate_errors([&] { throw ConfigError(message); }, kRenames);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("game.skill_rate_hz: must not exceed the physics rate 5 Hz (got 15)") ==
        "d.yaml:4:13: rates.skill_hz: must not exceed the physics rate 5 Hz (got 15)");
  CHECK(error_of("game.levels.localization.position_noise_m: must be >= 0 (got -1)") ==
        "d.yaml:6:21: levels.position_noise_m: must be >= 0 (got -1)");
  // Of two renames, the one the document has: robots.each[1].name, world.robots[0].jersey.
  CHECK(error_of("robots[1].name: duplicate robot name 'a'") ==
        "d.yaml:10:14: robots.each[1].name: duplicate robot name 'a'");
  CHECK(error_of("robots[0].jersey: must be in 1..99") ==
        "d.yaml:13:25: world.robots[0].jersey: must be in 1..99");
  // "game" -> the root: a key the document lacks is named at the top.
  CHECK(error_of("game.handling.align_s: must be at most 60 s") ==
        "d.yaml:1:1: handling.align_s: must be at most 60 s");
  // Without renames, as before: the path stays.
  try {
    root.locate_errors([] { throw ConfigError("game.skill_rate_hz: too high"); });
  } catch (const ConfigError& e) {
    CHECK(std::string(e.what()) == "d.yaml:1:1: game.skill_rate_hz: too high");
  }
}
