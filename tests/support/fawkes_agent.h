// SPDX-License-Identifier: MIT
// The Fawkes-style test agents' blackboard prologue (docs/fawkes.md), written once for the agent
// host's tests (tests/clips) and the scenario tests (tests/study).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "support/temp_dir.h"

namespace llsf::test {

/// An interface a Fawkes-style agent opens for reading: its type and id.
struct BlackboardOpen {
  std::string type, id;
};

/// The CLIPS text of the rule use-blackboard: once the host offers the blackboard feature, it
/// requests it, enables time reads, opens `opens` for reading in order, and path-loads `then_load`
/// (a path in the agent directory), whose rules may match the interface templates the opens have
/// just defined.
inline std::string blackboard_prologue(const std::vector<BlackboardOpen>& opens,
                                       const std::string& then_load) {
  std::string text =
      "\n(defrule use-blackboard\n"
      "  (ff-feature blackboard)\n"
      "  =>\n"
      "  (ff-feature-request \"blackboard\")\n"
      "  (blackboard-enable-time-read)\n";
  for (const BlackboardOpen& o : opens) {
    text += "  (blackboard-open \"" + o.type + "\" \"" + o.id + "\")\n";
  }
  text += "  (path-load " + then_load + "))\n";
  return text;
}

/// Writes the Fawkes-style agent `name` into the agent directory `agent_dir` of `dir` ("" for
/// `dir` itself): its entry file NAME/NAME.clp, the blackboard prologue opening `opens`, and
/// NAME/sense.clp, which the prologue path-loads, with `rules`. Returns the entry file's path.
inline std::string write_blackboard_agent(const TempDir& dir, const std::string& agent_dir,
                                          const std::string& name,
                                          const std::vector<BlackboardOpen>& opens,
                                          const std::string& rules) {
  const std::string folder = agent_dir.empty() ? name : agent_dir + "/" + name;
  std::filesystem::create_directories(dir.path / folder);
  dir.write(folder + "/" + name + ".clp", blackboard_prologue(opens, name + "/sense.clp"));
  dir.write(folder + "/sense.clp", rules);
  return dir.file(folder + "/" + name + ".clp");
}

}  // namespace llsf::test
