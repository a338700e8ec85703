// SPDX-License-Identifier: MIT
// A batch's identity covers the files its games load: editing an agent or a skill makes a new
// batch (a rerun plays instead of reusing stored results); other files do not count.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"

using namespace llsf::study;

TEST_CASE("batch_identity_hash: the scenario, its agent files and its skill files") {
  const auto dir = std::filesystem::temp_directory_path() / "llsf_batch_identity";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "agent");
  std::filesystem::create_directories(dir / "skills");
  auto write = [&dir](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
  };
  write("agent/a.clp", "(defrule a (time $?) => )\n");
  write("skills/my.lua", "-- a skill\n");
  write("notes.txt", "not loaded by any game\n");
  // (skill_dirs relative to the scenario file, as agent entries are)
  write("s.yaml", "name: id\nrobots: {count: 1, agent: [agent]}\nskills: {skill_dirs: [skills]}\n");
  const std::string scenario = (dir / "s.yaml").string();
  auto id = [&scenario] { return batch_identity_hash(scenario, load_scenario(scenario)); };
  const std::string first = id();
  CHECK(first.size() == 16);
  CHECK(id() == first);  // deterministic
  write("notes.txt", "edited\n");
  CHECK(id() == first);  // not part of any game
  write("agent/a.clp", "(defrule a (time $?) => (assert (x)))\n");
  const std::string agent_edited = id();
  CHECK(agent_edited != first);
  write("skills/my.lua", "-- a skill, edited\n");
  const std::string skill_edited = id();
  CHECK(skill_edited != agent_edited);
  write("agent/b.clp", "(defrule b (time $?) => )\n");  // a new agent file
  CHECK(id() != skill_edited);
  std::filesystem::remove_all(dir);
}
