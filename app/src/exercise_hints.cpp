// SPDX-License-Identifier: MIT
// Friendly errors of the exercises (exercise_hints.h).
#include "exercise_hints.h"

#include <cctype>
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

namespace {

/// Whether `msg` has a Lua position ("file.lua:12: "), i.e. it is an error Lua or the engine
/// raised at a line (not a text the skill declared with error= or self.fsm.error).
bool has_position(const std::string& msg) {
  for (std::size_t at = msg.find(".lua:"); at != std::string::npos;
       at = msg.find(".lua:", at + 1)) {
    std::size_t i = at + 5;
    while (i < msg.size() && std::isdigit(static_cast<unsigned char>(msg[i])) != 0) ++i;
    if (i > at + 5 && i + 1 < msg.size() && msg[i] == ':' && msg[i + 1] == ' ') return true;
  }
  return false;
}

}  // namespace

/// A hint for a Lua or skill error message.
std::string hint_for(const std::string& msg, const std::string& skill) {
  auto has = [&](const char* s) { return msg.find(s) != std::string::npos; };
  // The mistakes of docs/exercises.md, "Mistakes and their messages" (their messages are the
  // engine's, lua/src/prelude.lua), before the generic Lua errors below.
  if (has("is not available in skills")) {
    return "skills run in a sandbox without os, io, require, load, dofile, debug and coroutine: "
           "use what the message names instead (docs/skills.md, \"Sandbox\").";
  }
  if (has("execute() returned")) {
    return "execute() must return S_RUNNING, S_FINAL or S_FAILED on every path: a function "
           "that ends without `return` returns nil (check the branches of its if/else).";
  }
  if (has("if it is a state, no state is defined yet")) {
    return "a name the file uses before defining it: a state exists only after "
           "fsm:define_states{ export_to=_M, ... }; a constant needs `local NAME = value` above "
           "its first use; or it is a typo.";
  }
  if (has("fsm:define_states{...} is missing") || has("no state is defined yet")) {
    return "define the states right after SkillHSM:new: fsm:define_states{ export_to=_M, "
           "{\"DRIVE\", SkillJumpState, skills={{drive_to}}, final_to=\"FINAL\"}, ... }, then "
           "fsm:add_transitions{...} and the state functions (function DRIVE:init() ...).";
  }
  if (has("undeclared global 'fsm'") || has("has no state machine")) {
    return "create the state machine below name = ...: fsm = SkillHSM:new{name=name, "
           "start=\"DRIVE\"}, then fsm:define_states{...} (the exercise's skill.lua shows the "
           "layout).";
  }
  if (has("needs start=")) {
    return "name the state the skill begins in: fsm = SkillHSM:new{name=name, start=\"DRIVE\"} "
           "(a state of your fsm:define_states{...}).";
  }
  if (has("declares no 'documentation'")) {
    return "every skill says what it does: add documentation = [==[Drives to a point.]==] below "
           "name = ... (any text).";
  }
  if (has("declares no 'name'")) {
    return "add name = \"" + skill +
           "\" as the first line: the exercise loads your file as that "
           "skill.";
  }
  if (has("unknown state '")) {
    return "a state named in a transition, final_to, fail_to, timeout or start is not defined: "
           "fix the spelling (the message names the nearest state and lists them; names are "
           "case-sensitive) or add the state to fsm:define_states{...}.";
  }
  if (has("undeclared global") && has("did you mean")) {
    return "a typo? Use the name the message suggests (names are case-sensitive); a state's "
           "name is a global once fsm:define_states{ export_to=_M, ... } defined it.";
  }
  if (has("undeclared global")) {
    return "a name the skill never defined: make it a local (local n = 0) before use, declare "
           "interfaces in depends_interfaces and skills in depends_skills (names are "
           "case-sensitive).";
  }
  if (has("fsm.result must be")) {
    return "report text, not a table: self.fsm.result = string.format(\"%.2f %.2f\", x, y) "
           "(field coordinates), or a number.";
  }
  if (has("to 'printf'") || has("to 'format'") || has("to 'string.format'")) {
    return "the format does not fit the value: %d needs a whole number (use %.2f for 1.5, %s "
           "for anything, math.floor(v) to round down).";
  }
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
    return "the skill holds more memory than allowed (its heap limit): a table that grows every "
           "cycle (the line named is where the memory ran out)? Keep only what you need, e.g. "
           "the last few sightings.";
  }
  if (has("does not match its file name")) {
    return "the exercise loads your file as the skill '" + skill + "': keep the line name = \"" +
           skill + "\".";
  }
  if (has("(method '") && has("did you mean")) {
    return "the interface has no such method: use the name the message suggests (the "
           "interfaces' methods: docs/skills.md; call them with `:`, puck_detector:nearest()).";
  }
  if (has("`=` assigns; a condition compares with `==`")) {
    return "in a cond string write `==` to compare (`~=` for not equal): cond=\"vars.n == 3\".";
  }
  if (has("needs place=<name> or x=, y=:")) {
    return "the arguments your skill gave drive_to are wrong (the message says which): x and y "
           "are numbers (tonumber(\"1.5\") is 1.5), place a place name; set them in "
           "self.args[\"drive_to\"] in the state's init().";
  }
  if (has("'end' expected")) {
    return "a block is not closed: check the `end` of the function, `if` or state above (every "
           "function, if, for and while needs its own `end`).";
  }
  if (has("'}' expected") || has("')' expected")) {
    return "a table or call is not closed: look for a missing `,` between entries or a missing "
           "`}` / `)` on this line or the one above.";
  }
  // Lua's syntax errors end "near '<token>'" or "near <eof>" (not any text with "near" or
  // "expected" in it: `nearest`, "expected S_RUNNING").
  if (has("unexpected symbol") || has(" near '") || has(" near <eof>") || has(" near \"")) {
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
  if (has("bad argument #")) {
    return "a library function got a wrong argument: the message says which (#1 is the first) "
           "and what it expected.";
  }
  if (has_position(msg)) {
    return "a Lua error at this line: the message says which value was wrong (print it with "
           "print(...) just before the line to see it).";
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
