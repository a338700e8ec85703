// SPDX-License-Identifier: MIT
// check_agent() (source_check.h): `llsfsim check`'s static checks of an agent's files, on the
// source reader (source_text.h), so that comments and strings are not taken for code.
#include <algorithm>
#include <cctype>
#include <set>
#include <string_view>

#include "llsf/clips/source_check.h"  // check_agent()
#include "llsf/core/text.h"
#include "source_text.h"

namespace llsf::clips {

namespace {

using detail::SourceNode;
using Kind = AgentFinding::Kind;

bool is_symbol_start(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_';
}

// A plain symbol as a skill call's argument name: letters, digits, _ and -.
bool is_argument_name(const SourceNode& n) {
  if (n.kind != SourceNode::Kind::kAtom || n.text.empty()) return false;
  return std::all_of(n.text.begin(), n.text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-';
  });
}

// The literal argument names of a `(skill-call NAME key value key value ...)`: each key that is
// a plain symbol followed by a value; stops at anything else (a variable or an expression in a
// key's place).
std::vector<std::string> skill_call_arguments(const SourceNode& call) {
  std::vector<std::string> out;
  for (std::size_t k = 2; k + 1 < call.items.size() && is_argument_name(call.items[k]); k += 2) {
    out.push_back(call.items[k].text);
  }
  return out;
}

bool is_confval_path(const SourceNode& n) {
  return n.kind == SourceNode::Kind::kString && n.text.starts_with("/clips-agent/") &&
         std::none_of(n.text.begin(), n.text.end(),
                      [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; });
}

// What one file's code holds, in text order.
struct FileUses {
  std::vector<const SourceNode*> skill_calls;  ///< `(skill-call NAME ...)` with a symbol NAME
  std::vector<const SourceNode*> confvals;     ///< strings "/clips-agent/..."
  bool locks = false;  ///< a resource-request symbol, a (lock ...) or (lock-assert ...) list
};

void collect(const SourceNode& n, FileUses& uses) {
  if (n.kind == SourceNode::Kind::kString) {
    if (is_confval_path(n)) uses.confvals.push_back(&n);
    return;
  }
  if (n.kind == SourceNode::Kind::kAtom) {
    if (n.text.find("resource-request") != std::string::npos) uses.locks = true;
    return;
  }
  const std::string_view head = n.head();
  if (head == "lock" || head == "lock-assert") uses.locks = true;
  if (head == "skill-call" && n.items.size() >= 2 && n.items[1].kind == SourceNode::Kind::kAtom &&
      is_symbol_start(n.items[1].text.front())) {
    uses.skill_calls.push_back(&n);
  }
  for (const SourceNode& c : n.items) collect(c, uses);
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Paths are compared after the shared "/clips-agent/": on whole paths the long prefix made any
// two short keys "near" (speed and roles).
std::string key_of(const std::string& p) {
  constexpr std::string_view kPrefix = "/clips-agent/";
  return p.starts_with(kPrefix) ? p.substr(kPrefix.size()) : p;
}

}  // namespace

std::string AgentFinding::text() const {
  if (file.empty()) return message;
  if (line <= 0) return file + ": " + message;
  return file + ":" + std::to_string(line) + ": " + message;
}

std::vector<AgentFinding> check_agent(const std::vector<SourceFile>& files,
                                      const AgentCheckFacts& facts) {
  std::vector<AgentFinding> out;
  auto warn = [&out](Kind kind, std::string file, int line, std::string message) {
    out.push_back({kind, false, std::move(file), line, std::move(message)});
  };
  std::vector<std::string> skill_names;
  if (facts.skills) {
    for (const SkillFacts& s : *facts.skills) skill_names.push_back(s.name);
  }
  std::vector<std::string> read_paths;  // literal paths in the agent (a trailing / is a prefix)
  std::vector<std::string> read_where;  // each one's file:line
  bool uses_locks = false;
  TimeReadCheck time_reads;  // the files in load order
  for (const SourceFile& f : files) {
    for (const SourceWarning& w : time_reads.scan(f.text)) {
      warn(Kind::kTimeRead, f.name, w.line, w.message);
    }
    const std::vector<SourceNode> forms = detail::read_source(f.text);
    FileUses uses;
    for (const SourceNode& form : forms) collect(form, uses);
    uses_locks = uses_locks || uses.locks;
    // Skill calls: the skill's name, then the literal argument names it does not declare.
    for (const SourceNode* call : uses.skill_calls) {
      if (!facts.skills) break;
      const std::string& name = call->items[1].text;
      const auto skill = std::find_if(facts.skills->begin(), facts.skills->end(),
                                      [&name](const SkillFacts& s) { return s.name == name; });
      if (skill != facts.skills->end()) {
        const std::vector<std::string>& known = skill->params;
        if (known.empty()) continue;  // a skill without @param lines: nothing to compare with
        for (const std::string& arg : skill_call_arguments(*call)) {
          if (std::find(known.begin(), known.end(), arg) != known.end()) continue;
          const auto meant = core::closest_match(arg, known);
          warn(Kind::kUnknownArgument, f.name, call->line,
               "(skill-call " + name + " " + arg + " ...): " + name + " has no argument '" + arg +
                   "' (" + (meant ? "did you mean '" + *meant + "'? " : "") +
                   "its arguments: " + joined(known) + ")");
        }
        continue;
      }
      const auto hint = core::closest_match(name, skill_names);
      warn(
          Kind::kUnknownSkill, f.name, call->line,
          "(skill-call " + name + " ...): the skill library has no skill '" + name + "'" +
              (hint ? " (did you mean '" + *hint + "'?)" : " (`llsfsim skill --list` lists them)"));
    }
    for (const SourceNode* s : uses.confvals) {
      read_paths.push_back(s->text);
      read_where.push_back(f.name + ":" + std::to_string(s->line));
    }
  }

  // Configured paths the agent does not name.
  auto read_by_agent = [&read_paths](const std::string& path) {
    return std::any_of(read_paths.begin(), read_paths.end(), [&path](const std::string& p) {
      return p == path || (p.ends_with('/') && path.starts_with(p));
    });
  };
  std::vector<std::string> read_keys;  // read_paths' keys, same order
  for (const std::string& p : read_paths) read_keys.push_back(key_of(p));
  std::vector<std::string> set_paths;
  for (const ConfigEntry& e : facts.config) {
    if (e.path == "/clips-agent/use-locks") continue;  // the host's (AgentConfig::locks)
    if (facts.fawkes && e.path == "/clips-agent/agent") continue;  // the host's (its entry)
    set_paths.push_back(e.path);
    if (read_by_agent(e.path)) continue;
    // Either side may hold the typo: name the near path the agent reads and where, not a fix.
    std::string near;
    if (const auto hint = core::closest_match(key_of(e.path), read_keys)) {
      const auto i = static_cast<std::size_t>(std::find(read_keys.begin(), read_keys.end(), *hint) -
                                              read_keys.begin());
      near = "; it reads " + read_paths[i] + " (" + read_where[i] + "): one of the two is misspelt";
    } else if (read_paths.empty()) {
      near = "; its files name no /clips-agent/ path at all";
    } else {
      // No path near it: name what the agent reads, so the one meant can be found.
      const std::set<std::string> all(read_paths.begin(), read_paths.end());
      std::string list;
      int shown = 0;
      for (const std::string& p : all) {
        if (shown++ == 8) break;
        list += (list.empty() ? "" : ", ") + p;
      }
      near = "; it reads " + list +
             (all.size() > 8 ? ", ... (" + std::to_string(all.size()) + " paths)" : "");
    }
    warn(Kind::kConfvalNotRead, facts.config_name, 0,
         "the agent reads no confval " + e.path + near);
  }

  // Paths the agent names that the configuration leaves out.
  std::sort(read_paths.begin(), read_paths.end());
  read_paths.erase(std::unique(read_paths.begin(), read_paths.end()), read_paths.end());
  std::vector<std::string> unset;
  for (const std::string& p : read_paths) {
    if (p.ends_with('/') || p == "/clips-agent/use-locks") continue;
    if (std::find(set_paths.begin(), set_paths.end(), p) != set_paths.end()) continue;
    unset.push_back(p);
  }
  if (!unset.empty()) {
    out.push_back({Kind::kConfvalsDefault, true, "", 0,
                   facts.config_name +
                       " leaves these confvals of the agent at its defaults: " + joined(unset)});
  }
  if (facts.locks && !uses_locks) {
    warn(Kind::kLocksUnused, "", 0,
         facts.locks_name +
             " is on, but the agent uses no lock facts (no resource-request or lock fact in its "
             "files): the lock protocol runs for nothing (set `" +
             facts.locks_name + ": false`?)");
  }
  return out;
}

}  // namespace llsf::clips
