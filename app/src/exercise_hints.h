// SPDX-License-Identifier: MIT
// Friendly errors of `llsfsim exercise` and `llsfsim skill`-style runs: a Lua or skill error
// message shown in the participant's terms (their file and line, never the temporary copy's),
// with a hint that names the mistake (docs/exercises.md, "Mistakes and their messages").
#pragma once

#include <iosfwd>
#include <string>

namespace llsf::app {

/// Replaces the temporary skill path `tmp` in `text` (also as Lua shortens it: "...tail") by
/// the participant's path `user`.
std::string user_paths(std::string text, const std::string& tmp, const std::string& user);

/// A hint for a Lua or skill error message of the skill `skill`.
std::string hint_for(const std::string& msg, const std::string& skill);

/// Prints `message` (an engine error) in the participant's terms: "error    file:line: text",
/// "in       context" and "hint     ...".
void print_friendly(const std::string& message, const std::string& tmp, const std::string& user,
                    const std::string& skill, std::ostream& out);

}  // namespace llsf::app
