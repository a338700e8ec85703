// SPDX-License-Identifier: MIT
// Friendly errors of the exercises (exercise_hints.h).
#include "exercise_hints.h"

#include <filesystem>
#include <ostream>
#include <string>

namespace llsf::app {

namespace fs = std::filesystem;

/// Replaces the temporary skill path in `text` (also as Lua shortens it: "...tail") by the
/// participant's path.
std::string user_paths(std::string text, const std::string& tmp, const std::string& user) {
  const std::string base = fs::path(tmp).filename().string();
  std::size_t pos = 0;
  while ((pos = text.find(base, pos)) != std::string::npos) {
    // The path token ends after base and starts after a space, quote or the text's start.
    std::size_t start = pos;
    while (start > 0 && text[start - 1] != ' ' && text[start - 1] != '\'' &&
           text[start - 1] != '"' && text[start - 1] != '(') {
      --start;
    }
    const std::string token = text.substr(start, pos + base.size() - start);
    const bool ours =
        token == tmp ||
        (token.rfind("...", 0) == 0 && tmp.size() >= token.size() - 3 &&
         tmp.compare(tmp.size() - (token.size() - 3), token.size() - 3, token.substr(3)) == 0);
    if (!ours) {
      pos += base.size();
      continue;
    }
    text.replace(start, token.size(), user);
    pos = start + user.size();
  }
  return text;
}

/// A hint for a Lua or skill error message.
std::string hint_for(const std::string& msg, const std::string& skill) {
  auto has = [&](const char* s) { return msg.find(s) != std::string::npos; };
  if (has("pattern matching)") || has("plain search)")) {
    return "a string search that takes too long: a pattern with several `*`, `+` or `-` on a "
           "long string backtracks a lot; search a shorter string or use a simpler pattern "
           "(docs/skills.md, \"Sandbox\").";
  }
  if (has("instruction budget exhausted (") && has(" elements)")) {
    return "a table function over too many elements in one cycle (table.move, table.concat, "
           "table.insert at the front of a long list ...): check its range, or spread the work "
           "over several cycles.";
  }
  if (has("string.rep: result of")) {
    return "string.rep would build a string bigger than the skill's memory: check its count.";
  }
  if (has("allocation budget exhausted")) {
    return "the skill copies too much memory in one cycle (e.g. `s = s .. x` or s:upper() on a "
           "big string in a loop): build strings with table.concat, or do less per cycle.";
  }
  if (has("is read-only (shared by every skill)")) {
    return "the libraries (string, table, math, utf8) and the DSL's classes are shared by every "
           "skill and cannot be changed: use a local variable (local fmt = function ... end).";
  }
  if (has("instruction budget exhausted")) {
    return "an endless loop: hooks and conditions run once per skill cycle (30 times a second) "
           "and must return quickly. Do not wait in a `while` loop; add a state and a "
           "transition (cond=..., timeout=...) that waits instead.";
  }
  if (has("not enough memory")) {
    return "the skill used more memory than allowed (its heap limit): a table that grows every "
           "cycle?";
  }
  if (has("does not match its file name")) {
    return "the exercise loads your file as the skill '" + skill + "': keep the line name = \"" +
           skill + "\".";
  }
  if (has("'end' expected")) {
    return "a block is not closed: check the `end` of the function, `if` or state above (every "
           "function, if, for and while needs its own `end`).";
  }
  if (has("'}' expected") || has("')' expected")) {
    return "a table or call is not closed: look for a missing `,` between entries or a missing "
           "`}` / `)` on this line or the one above.";
  }
  if (has("unexpected symbol") || has("near") || has("expected")) {
    return "a syntax error: check this line and the one above (a missing `then`, `do`, `end`, "
           "`,` or quote; `=` vs `==`).";
  }
  if (has("is used but not declared")) {
    return "declare it at the top of the file, as the message says (depends_skills / "
           "depends_interfaces).";
  }
  if (has("unknown skill") || has("unknown interface") || has("unknown type")) {
    return "only library skills and interfaces exist (docs/skills.md; the exercise's README.md "
           "lists the ones to use).";
  }
  if (has("attempt to call a nil value")) {
    return "calling something that does not exist: check the spelling, and call interface "
           "methods with `:` (pose:x(), not pose.x()).";
  }
  if (has("a nil value") || has("attempt to compare") || has("nil")) {
    return "something is nil: an argument that was not passed, a self.fsm.vars entry not set "
           "yet, or a call that returned nothing (puck_detector:nearest() with no puck in "
           "sight returns nothing).";
  }
  if (has("not solved yet")) {
    return "this is the unchanged skeleton: fill in the TODOs of the skill file (the "
           "exercise's README.md explains the goal and gives hints).";
  }
  if (has(")/")) {
    return "a skill your skill called failed: send the state to a recovery state with "
           "fail_to=\"STATE\" and try again, instead of failing.";
  }
  return "your skill failed with this error (a transition to FAILED or self.fsm.error).";
}

/// Prints `message` (an engine error) in the participant's terms: "error: file:line: text",
/// "in: context" and a hint.
void print_friendly(const std::string& message, const std::string& tmp, const std::string& user,
                    const std::string& skill, std::ostream& out) {
  const std::string text = user_paths(message, tmp, user);
  const std::size_t at = text.find(user + ":");
  if (at != std::string::npos) {
    std::string context = text.substr(0, at);
    while (!context.empty() && (context.back() == ' ' || context.back() == ':')) {
      context.pop_back();
    }
    out << "error    " << text.substr(at) << "\n";
    if (!context.empty()) out << "in       " << context << "\n";
  } else {
    out << "error    " << text << "\n";
  }
  out << "hint     " << hint_for(text, skill) << "\n";
}

}  // namespace llsf::app
