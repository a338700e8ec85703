// SPDX-License-Identifier: MIT
// AgentHost: the cycle (assert what is new, run to quiescence within the firing limit, clean up),
// loading with file:line errors, output routing to the log sink, runtime-error containment.
#include "llsf/clips/agent.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "feature.h"
#include "llsf/clips/source_check.h"
#include "llsf/core/config.h"
#include "llsf/core/input_file.h"
#include "llsf/core/text.h"
#include "sandbox.h"
#include "source_text.h"
#include "tracer.h"

namespace llsf::clips {

const char* to_string(SkillStatus status) {
  switch (status) {
    case SkillStatus::kIdle:
      return "IDLE";
    case SkillStatus::kRunning:
      return "RUNNING";
    case SkillStatus::kFinal:
      return "FINAL";
    case SkillStatus::kFailed:
      return "FAILED";
  }
  return "IDLE";
}

const char* to_string(AgentIssueKind kind) {
  switch (kind) {
    case AgentIssueKind::kRuntimeError:
      return "runtime-error";
    case AgentIssueKind::kRuleLoop:
      return "rule-loop";
  }
  return "runtime-error";
}

const char* to_string(AgentEventKind kind) {
  switch (kind) {
    case AgentEventKind::kRoleChange:
      return "role-change";
  }
  return "role-change";
}

const char* to_string(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarn:
      return "warn";
    case LogLevel::kError:
      return "error";
  }
  return "info";
}

void AgentConfig::validate() const {
  if (robot_name.empty() || robot_name.find_first_of(" \t\n()\"&|<~;?$") != std::string::npos)
    throw std::invalid_argument("AgentConfig.robot_name must be a CLIPS symbol, got \"" +
                                robot_name + "\"");
  if (robot_number < 0) throw std::invalid_argument("AgentConfig.robot_number must be >= 0");
  if (max_rules_per_cycle <= 0)
    throw std::invalid_argument("AgentConfig.max_rules_per_cycle must be > 0");
  if (max_steps_per_cycle <= 0)
    throw std::invalid_argument("AgentConfig.max_steps_per_cycle must be > 0");
  if (!(max_cycle_wall_s > 0.0))
    throw std::invalid_argument("AgentConfig.max_cycle_wall_s must be > 0");
  if (max_call_depth <= 0) throw std::invalid_argument("AgentConfig.max_call_depth must be > 0");
  if (max_memory_bytes <= 0)
    throw std::invalid_argument("AgentConfig.max_memory_bytes must be > 0");
  if (max_string_length <= 0)
    throw std::invalid_argument("AgentConfig.max_string_length must be > 0");
  if (max_multifield_length <= 0)
    throw std::invalid_argument("AgentConfig.max_multifield_length must be > 0");
  if (locks) lock_config.validate();
}

const Value& Fact::slot(std::string_view name) const {
  for (const auto& [n, v] : slots)
    if (n == name) return v;
  throw std::out_of_range("fact of " + template_name + " has no slot " + std::string(name));
}

namespace {

// Collapses whitespace runs (CLIPS error messages span several lines).
std::string one_line(std::string_view s) {
  std::string out;
  bool space = false;
  for (char c : s) {
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += c;
  }
  return out;
}

constexpr std::string_view kLocksClp = "builtin/locks.clp";
constexpr std::string_view kFawkesClp = "builtin/fawkes.clp";

LogLevel level_of(std::string_view logical_name) {
  if (logical_name == "debug" || logical_name == "wtrace") return LogLevel::kDebug;
  if (logical_name == "warn" || logical_name == "wwarning") return LogLevel::kWarn;
  if (logical_name == "error") return LogLevel::kError;
  return LogLevel::kInfo;
}

}  // namespace

struct AgentHost::Impl {
  detail::HostState state;
  std::pair<std::string, std::string> interface_key;  // write_interface's look-up
  detail::Environment env;  // before the features: they hold handles into it
  std::vector<std::unique_ptr<detail::Feature>> features;
  bool started = false;
  int runtime_errors = 0;
  int limit_hits = 0;
  std::int64_t rules_fired = 0;
  std::string werror;         // CLIPS error output not yet reported
  std::string werror_rule;    // the rule whose actions ran when `werror` began ("" if none)
  std::string lines[4];       // partial output lines per level
  std::string budget_reason;  // set when the work budget stopped the cycle
  // Where a construct starts.
  struct Place {
    std::string file;
    int line = 0;
  };
  std::unordered_map<std::string, Place> rule_places;      // defrule name -> its place
  std::unordered_map<std::string, Place> function_places;  // deffunction -> its place
  std::int64_t max_steps_seen = 0;
  std::unique_ptr<detail::Tracer> tracer;  // set_trace()
  TimeReadCheck time_check;                // over the files in load order
  // Fawkes' agent model (AgentConfig::fawkes).
  bool fawkes_started_ = false;
  std::vector<std::string>* load_failures_ = nullptr;  // while the entry file runs
  // Fawkes' search path (path-add, ...): directories, the agent directory at first.
  std::vector<std::string> search_path_;
  std::vector<std::pair<std::string, std::string>> path_subst_;  // path-add-subst
  std::string batch_place_;  // "entry.clp:LINE" of the command being evaluated

  ~Impl() { env.observe(nullptr, false, false); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  Impl(AgentConfig config, AgentIo io) {
    config.validate();
    state.config = std::move(config);
    state.io = std::move(io);
    if (state.io.broadcast) {  // the trace sees every broadcast (pb-broadcast, lock messages)
      state.io.broadcast =
          [this, out = std::move(state.io.broadcast)](const google::protobuf::Message& m) {
            if (tracer) tracer->message_out(m);
            out(m);
          };
    }
    state.log = [this](LogLevel level, std::string_view text) { emit(level, text); };
    env.set_size_limits({state.config.max_memory_bytes, state.config.max_string_length,
                         state.config.max_multifield_length});
    env.set_output_handler(
        [this](std::string_view name, std::string_view text) { on_output(name, text); });
    // Fixed order: functions first (the built-in code may call them), then the code, then the
    // template look-ups.
    features.push_back(detail::make_log_feature(state));
    features.push_back(detail::make_random_feature(state));
    features.push_back(detail::make_robot_feature(state));
    features.push_back(detail::make_time_feature(state));
    features.push_back(detail::make_config_feature(state));
    features.push_back(detail::make_skills_feature(state));
    features.push_back(detail::make_locks_feature(state));  // before protobuf: takes lock messages
    features.push_back(detail::make_protobuf_feature(state));
    features.push_back(detail::make_fawkes_feature(state));
    features.push_back(detail::make_blackboard_feature(state));
    for (auto& f : features) f->define(env);
    if (state.config.fawkes) define_fawkes_functions();
    for (int i = 0; i < detail::kBuiltinCodeCount; ++i) {
      // Without locks the lock template stays free for the agent's own (e.g. a Fawkes lock.clp).
      const std::string_view name = detail::kBuiltinCode[i].name;
      if (!state.config.locks && name == kLocksClp) continue;
      if (!state.config.fawkes && name == kFawkesClp) continue;
      load(detail::kBuiltinCode[i].text, name);
    }
    // A Fawkes-style agent may (reset): the host's own reset (define_fawkes_functions) replaces
    // CLIPS', so that the host's facts come back after it.
    static constexpr std::string_view kFawkesAllowed[] = {"reset"};
    if (state.config.sandbox) {
      detail::install_sandbox(env, state.config.fawkes
                                       ? std::span<const std::string_view>(kFawkesAllowed)
                                       : std::span<const std::string_view>());
    }
    for (auto& f : features) f->bind(env);
  }

  // ---- Fawkes' agent model (docs/fawkes.md) ----------------------------------------------

  // path-load, path-resolve and (reset) for Fawkes-style agents.
  void define_fawkes_functions() {
    search_path_ = {state.config.agent_dir + "/"};
    // (path-load "dir/file.clp"): loads the constructs of a file of the agent directory, as
    // Fawkes' path-load (load*) did: TRUE, or FALSE after an error (a load error before the
    // game, a runtime error during it).
    env.define_function("path-load", "11k", [this](detail::Args& a) {
      std::string_view file;
      a.text(0, file);
      return Value::boolean(path_load(std::string(file)));
    });
    // (path-resolve "dir/file.clp"): the file's path, the first directory of the search path
    // that has it, else FALSE.
    env.define_function("path-resolve", "11k", [this](detail::Args& a) {
      std::string_view file;
      a.text(0, file);
      std::string why;
      const std::optional<std::string> p = resolve_on_path(std::string(file), why);
      return p ? Value::string(*p) : Value::boolean(false);
    });
    // Fawkes' search path (its path.clp): a list of directories, each put before the file name
    // as it is (so they end in "/"), the agent directory at first. Paths outside the agent
    // directory may be added but resolve no file (the sandbox). It survives a (reset), as in
    // Fawkes since December 2013.
    env.define_function("path-add", "0*k", [this](detail::Args& a) {
      for (int i = 0; i < a.count(); ++i) {
        std::string_view p;
        a.text(i, p);
        std::string dir(p);
        for (const auto& [what, by] : path_subst_) {
          if (const std::size_t at = dir.find(what); at != std::string::npos)
            dir.replace(at, what.size(), by);
        }
        search_path_.push_back(std::move(dir));
      }
      return Value{};
    });
    env.define_function("path-add-subst", "22k", [this](detail::Args& a) {
      std::string_view what, by;
      a.text(0, what);
      a.text(1, by);
      path_subst_.emplace_back(what, by);
      return Value{};
    });
    env.define_function("path-reset", "00", [this](detail::Args&) {
      search_path_.clear();
      path_subst_.clear();
      return Value{};
    });
    env.define_function("path-get", "00", [this](detail::Args&) {
      std::vector<Value> out;
      for (const std::string& d : search_path_) out.push_back(Value::string(d));
      return Value::multifield(std::move(out));
    });
    env.define_function("path-string", "00", [this](detail::Args&) {
      std::string out;
      for (const std::string& d : search_path_) out += (out.empty() ? "" : ":") + d;
      return Value::string(out);
    });
    env.define_function("reset", "00", [this](detail::Args&) {
      reset_env();
      return Value{};
    });
  }

  // `file` inside the agent directory (relative to it), or nullopt with the reason in `why`.
  std::optional<std::string> resolve_agent_file(const std::string& file, std::string& why) const {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fs::weakly_canonical(fs::path(state.config.agent_dir), ec);
    if (ec || state.config.agent_dir.empty()) {
      why = "the agent has no agent directory";
      return std::nullopt;
    }
    const fs::path rel(file);
    const fs::path p = fs::weakly_canonical(rel.is_absolute() ? rel : dir / rel, ec);
    const auto [d_end, p_it] = std::mismatch(dir.begin(), dir.end(), p.begin(), p.end());
    if (ec || d_end != dir.end()) {
      why = file + " is outside the agent directory " + dir.string() +
            " (the sandbox reads only the agent's own files; docs/security.md)";
      return std::nullopt;
    }
    if (!fs::is_regular_file(p, ec)) {
      why = "no file " + file + " in the agent directory " + dir.string();
      return std::nullopt;
    }
    return p.string();
  }

  // `file` in the first directory of the search path that has it (inside the agent
  // directory), or nullopt with the reason in `why`.
  std::optional<std::string> resolve_on_path(const std::string& file, std::string& why) {
    if (!file.empty() && file.front() == '/') return resolve_agent_file(file, why);
    std::string first_why;
    for (const std::string& dir : search_path_) {
      std::string w;
      // (the agent directory itself: the file as given, which the messages name)
      const bool home = dir == state.config.agent_dir + "/";
      if (auto p = resolve_agent_file(home ? file : dir + file, w)) return p;
      if (first_why.empty()) first_why = std::move(w);
    }
    why = search_path_.size() == 1 ? first_why
                                   : "no file " + file + " on the search path " + path_text() +
                                         (first_why.empty() ? "" : " (" + first_why + ")");
    if (search_path_.empty()) why = "no file " + file + ": the search path is empty (path-reset)";
    return std::nullopt;
  }
  std::string path_text() const {
    std::string out;
    for (const std::string& d : search_path_) out += (out.empty() ? "" : ":") + d;
    return out;
  }

  // Fawkes' own CLIPS files, which every Fawkes environment had loaded: llsfsim's built-in
  // equivalents are loaded already, so a path-load of one of them loads nothing.
  static bool fawkes_builtin_file(std::string_view file) {
    static constexpr std::string_view kFiles[] = {"utils.clp",     "time.clp",   "path.clp",
                                                  "ff-config.clp", "skills.clp", "init.clp",
                                                  "protobuf.clp"};
    return std::find(std::begin(kFiles), std::end(kFiles), file) != std::end(kFiles);
  }

  bool path_load(const std::string& file) {
    std::string why;
    const std::optional<std::string> p = resolve_on_path(file, why);
    if (!p) {
      if (fawkes_builtin_file(file)) return true;
      load_failure("path-load: " + why);
      return false;
    }
    std::string error;
    const auto text = core::try_read_input_file(*p, core::kMaxSourceBytes, "CLIPS file", error);
    if (!text) {
      load_failure("path-load: " + error);
      return false;
    }
    const std::vector<std::string> errors = load_collect(*text, *p);
    for (const std::string& e : errors) load_failure(e, /*located=*/true);
    return errors.empty();
  }

  // An error of loading an agent file: collected while the entry file runs (AgentLoadError at
  // its end), else a runtime error naming the rule that loaded it.
  // `located`: the text names its own file and line (a load error of a loaded file); otherwise
  // the place of the top-level command being run is put before it.
  void load_failure(std::string text, bool located = false) {
    if (load_failures_ != nullptr) {
      load_failures_->push_back(batch_place_.empty() || located ? std::move(text)
                                                                : batch_place_ + ": " + text);
      return;
    }
    report_runtime_error(env.executing_rule(), text);
  }

  // A runtime error: logged for people ("runtime error in rule NAME (FILE:LINE): text") and
  // reported as data (AgentIo::issues), counted.
  void report_runtime_error(const std::string& rule, const std::string& text) {
    if (rule.empty()) {
      emit(LogLevel::kError, "runtime error: " + text);
    } else {
      emit(LogLevel::kError,
           "runtime error in rule " + rule + place_of(rule_places, rule) + ": " + text);
    }
    issue(AgentIssueKind::kRuntimeError, rule, text);
    ++runtime_errors;
  }

  // Reports an issue as data.
  void issue(AgentIssueKind kind, const std::string& rule, std::string_view text) {
    if (!state.io.issues) return;
    AgentIssue i;
    i.time = state.now;
    i.kind = kind;
    i.agent = state.config.robot_name;
    i.rule = rule;
    if (const auto it = rule_places.find(rule); !rule.empty() && it != rule_places.end()) {
      i.file = it->second.file;
      i.line = it->second.line;
    }
    i.text = text;
    state.io.issues(i);
  }

  // CLIPS' (reset) for a Fawkes-style agent: the host's facts (ff-feature, robot-info, ...) are
  // asserted again after it.
  void reset_env() {
    env.reset();
    for (auto& f : features) f->after_reset(env);
  }

  // The top-level forms of a batch file: constructs and commands, with their first line (read
  // with the one scanner of CLIPS source, source_text.h).
  struct Form {
    std::size_t begin = 0, end = 0;
    int line = 1;
    bool construct = false;
  };
  static bool split_forms(const std::string& text, std::vector<Form>& out, std::string& error,
                          int& error_line) {
    static constexpr std::string_view kConstructs[] = {
        "defrule",    "deftemplate", "deffacts", "defglobal",    "deffunction",       "defmodule",
        "defgeneric", "defmethod",   "defclass", "definstances", "defmessage-handler"};
    detail::SourceScanner scanner(text);
    detail::SourceToken t;
    while (scanner.next(t)) {
      if (t.kind != detail::SourceToken::Kind::kOpen) {
        error = "expected a command or construct in parentheses";
        error_line = t.line;
        return false;
      }
      Form f;
      f.begin = t.begin;
      f.line = t.line;
      int depth = 1;
      while (depth > 0 && scanner.next(t)) {
        if (t.kind == detail::SourceToken::Kind::kOpen) {
          ++depth;
        } else if (t.kind == detail::SourceToken::Kind::kClose) {
          --depth;
        }
      }
      if (depth > 0) {
        error = "the form that starts here is not closed (a ')' is missing)";
        error_line = f.line;
        return false;
      }
      f.end = t.end;
      // A construct if the word right after its parenthesis (up to white space or a
      // parenthesis) is a construct's keyword.
      std::size_t k = f.begin + 1;
      while (k < f.end && std::isspace(static_cast<unsigned char>(text[k])) != 0) ++k;
      std::size_t e = k;
      while (e < f.end && std::isspace(static_cast<unsigned char>(text[e])) == 0 &&
             text[e] != '(' && text[e] != ')')
        ++e;
      const std::string_view word(text.data() + k, e - k);
      f.construct =
          std::find(std::begin(kConstructs), std::end(kConstructs), word) != std::end(kConstructs);
      out.push_back(f);
    }
    return true;
  }

  // Runs a batch file as CLIPS' batch* does: constructs are defined, commands evaluated, in
  // order. Errors go to load_failure() with the file and line.
  void batch(const std::string& text, const std::string& source) {
    std::vector<Form> forms;
    std::string error;
    int error_line = 0;
    const bool ok = split_forms(text, forms, error, error_line);
    for (std::size_t i = 0; i < forms.size();) {
      if (forms[i].construct) {
        // Consecutive constructs load as one piece, padded to keep their line numbers.
        std::size_t j = i;
        while (j + 1 < forms.size() && forms[j + 1].construct) ++j;
        std::string chunk(static_cast<std::size_t>(forms[i].line - 1), '\n');
        chunk.append(text, forms[i].begin, forms[j].end - forms[i].begin);
        for (std::string& e : load_collect(chunk, source)) load_failure(std::move(e), true);
        i = j + 1;
        continue;
      }
      flush_output();
      batch_place_ = source + ":" + std::to_string(forms[i].line);
      env.eval(text.substr(forms[i].begin, forms[i].end - forms[i].begin));
      if (!werror.empty()) {
        std::string msg = with_hint(one_line(werror));
        werror.clear();
        load_failure(std::move(msg));
      }
      batch_place_.clear();
      flush_output();
      env.clear_halt();
      ++i;
    }
    if (!ok) load_failure(source + ":" + std::to_string(error_line) + ": " + error, true);
  }

  // The start of a Fawkes-style agent (AgentConfig::fawkes), as Fawkes' clips-agent did it:
  // the feature facts, (agent-init), (config-load "/clips-agent"), the entry file as a batch
  // file, then the rules run to quiescence at time 0. Throws AgentLoadError with every load
  // error of the entry file and the files it path-loaded.
  void fawkes_start(const std::string& path) {
    if (fawkes_started_) {
      throw AgentLoadError(path +
                           ": a Fawkes-style agent has one entry file, which path-loads the "
                           "others (docs/fawkes.md)");
    }
    fawkes_started_ = true;
    std::string why;
    const std::optional<std::string> entry = resolve_agent_file(path, why);
    if (!entry) throw AgentLoadError(path + ": " + why);
    std::string error;
    const auto text = core::try_read_input_file(*entry, core::kMaxSourceBytes, "CLIPS file", error);
    if (!text) throw AgentLoadError(error);

    std::vector<std::string> failures;
    load_failures_ = &failures;
    env.start_budget(state.config.max_steps_per_cycle, state.config.max_cycle_wall_s,
                     state.config.max_call_depth);
    start(state.now);
    env.set_global("ROBOT-NAME", Value::symbol(state.config.robot_name));
    env.set_global("ROBOT-NUMBER", Value::integer_value(state.config.robot_number));
    env.set_global("TEAM-NAME", Value::string(state.config.team_name));
    env.eval("(ff-feature-request \"config\")");  // as the clips-agent requested it
    env.assert_string("(agent-init)");
    env.eval("(config-load \"/clips-agent\")");
    flush_output();
    batch(*text, *entry);
    CycleResult result;
    run_rules(result);
    flush_output();
    load_failures_ = nullptr;
    // /clips-agent/auto-start: the clips-agent asserted (start) once it had started (else when
    // a switch interface enabled it, which llsfsim has not).
    for (const ConfigEntry& c : state.config.config) {
      if (c.path == "/clips-agent/auto-start" && !c.values.empty() &&
          c.values.front() == Value::boolean(true))
        env.assert_string("(start)");
    }
    if (failures.empty()) return;
    std::string msg;
    for (const std::string& f : failures) {
      if (!msg.empty()) msg += '\n';
      msg += f;
    }
    throw AgentLoadError(msg);
  }

  void emit(LogLevel level, std::string_view text) {
    if (tracer) tracer->log(level, text);
    if (!state.io.log) return;
    state.io.log(LogRecord{state.now, level, state.config.robot_name, text});
  }

  // Output arrives in pieces; complete lines go to the sink, werror is collected as an error.
  // Both are bounded: error text beyond kMaxErrorText loses its middle, and a line longer than
  // max_string_length is logged in pieces of that size (a loop printing without a newline).
  void on_output(std::string_view name, std::string_view text) {
    if (name == "werror") {
      // The rule running when the error text began: named even when CLIPS does not halt it
      // (a build or undeftemplate that fails only returns FALSE).
      if (werror.empty()) werror_rule = env.executing_rule();
      werror.append(text);
      if (werror.size() > kMaxErrorText)  // keep the cause (head) and the halted rule (tail)
        werror.erase(kMaxErrorText / 2, werror.size() - kMaxErrorText);
      return;
    }
    const LogLevel level = level_of(name);
    std::string& buf = lines[static_cast<int>(level)];
    buf.append(text);
    std::size_t pos = 0;
    while ((pos = buf.find('\n')) != std::string::npos) {
      emit(level, std::string_view(buf).substr(0, pos));
      buf.erase(0, pos + 1);
    }
    const auto max_line = static_cast<std::size_t>(state.config.max_string_length);
    while (buf.size() > max_line) {
      emit(level, std::string_view(buf).substr(0, max_line));
      buf.erase(0, max_line);
    }
  }
  static constexpr std::size_t kMaxErrorText = 64 * 1024;

  void flush_output() {
    for (int i = 0; i < 4; ++i) {
      if (lines[i].empty()) continue;
      emit(static_cast<LogLevel>(i), lines[i]);
      lines[i].clear();
    }
    report_errors();
  }

  // CLIPS' message for a misspelt function or slot with the name meant: "Missing function
  // declaration for prinout." gets " (did you mean 'printout'?)", "Invalid slot plac not defined
  // in corresponding deftemplate job." the nearest slot of job.
  std::string with_hint(std::string msg) const {
    auto word_after = [&msg](std::string_view lead, std::size_t& end) -> std::string {
      const std::size_t at = msg.find(lead);
      if (at == std::string::npos) return {};
      const std::size_t b = at + lead.size();
      end = b;
      while (end < msg.size() && std::isspace(static_cast<unsigned char>(msg[end])) == 0) ++end;
      std::string w = msg.substr(b, end - b);
      while (!w.empty() && w.back() == '.') {
        w.pop_back();
        --end;
      }
      return w;
    };
    std::size_t end = 0;
    if (const std::string fn = word_after("Missing function declaration for ", end); !fn.empty()) {
      if (const auto m = core::closest_match(fn, env.callable_names())) {
        msg.insert(end, " (did you mean '" + *m + "'?)");
      }
      return msg;
    }
    std::size_t slot_end = 0;
    const std::string slot = word_after("Invalid slot ", slot_end);
    std::size_t tmpl_end = 0;
    const std::string tmpl = word_after("corresponding deftemplate ", tmpl_end);
    if (!slot.empty() && !tmpl.empty()) {
      const std::vector<std::string> slots = env.template_slot_names(tmpl);
      if (const auto m = core::closest_match(slot, slots)) {
        msg.insert(tmpl_end, " (did you mean '" + *m + "'?)");
      }
    }
    return msg;
  }

  // Logs collected error output as one runtime error, naming the rule CLIPS stopped.
  int report_errors() {
    if (werror.empty()) return 0;
    std::string rule;
    std::string_view text = werror;
    if (auto p = text.rfind("[PRCCODE4]"); p != std::string_view::npos) {
      const std::string_view halted = text.substr(p);
      if (auto q = halted.rfind("defrule "); q != std::string_view::npos) {
        rule = one_line(halted.substr(q + 8));
        while (!rule.empty() && (rule.back() == '.' || rule.back() == ' ')) rule.pop_back();
      }
      // Keep the cause; the "execution halted" line only names the rule.
      if (auto first = text.find("[PRCCODE4]"); first > 0) text = text.substr(0, first);
    }
    if (rule.empty()) rule = werror_rule;
    std::string msg = with_hint(one_line(text));
    if (!budget_reason.empty()) {
      msg = budget_reason;
      budget_reason.clear();
    }
    report_runtime_error(rule, msg);
    werror.clear();
    return 1;
  }

  // " (file:line)" of a rule or function, or "" if its place is unknown.
  static std::string place_of(const std::unordered_map<std::string, Place>& places,
                              const std::string& name) {
    const auto it = places.find(name);
    return it != places.end() ? " (" + it->second.file + ":" + std::to_string(it->second.line) + ")"
                              : std::string();
  }

  // Where each defrule and deffunction (defgeneric, defmethod) of `text` starts ("file:line"),
  // for messages that name one. Not with the scanner of source_text.h, which skips strings: this
  // reads them as code too, and so a rule built from a string at run time, (build "(defrule x
  // ...)"), has the place of the string.
  void note_rule_places(const std::string& text, std::string_view source) {
    const auto token_end = [&](std::size_t b) {
      std::size_t e = b;
      while (e < text.size() && std::isspace(static_cast<unsigned char>(text[e])) == 0 &&
             text[e] != '(' && text[e] != ')' && text[e] != ';')
        ++e;
      return e;
    };
    int line = 1;
    bool comment = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
      const char c = text[i];
      if (c == '\n') {
        ++line;
        comment = false;
      } else if (c == ';') {
        comment = true;
      } else if (!comment && c == '(' && text.compare(i + 1, 3, "def") == 0) {
        const std::size_t ke = token_end(i + 1);
        const std::string_view keyword(text.data() + i + 1, ke - i - 1);
        auto* places =
            keyword == "defrule" ? &rule_places
            : keyword == "deffunction" || keyword == "defgeneric" || keyword == "defmethod"
                ? &function_places
                : nullptr;
        if (places == nullptr) continue;
        std::size_t b = ke;
        while (b < text.size() && std::isspace(static_cast<unsigned char>(text[b])) != 0) ++b;
        const std::size_t e = token_end(b);
        if (e > b) (*places)[text.substr(b, e - b)] = Place{std::string(source), line};
      }
    }
  }

  // Why the work budget stopped a cycle, for the runtime error it logs.
  std::string budget_text() const {
    using Hit = detail::Environment::BudgetHit;
    switch (env.budget_hit()) {
      case Hit::kDepth: {
        const std::string& fn = env.budget_function();
        return "stopped at a call depth of " + std::to_string(state.config.max_call_depth) +
               " in " + fn + place_of(function_places, fn) +
               " (a recursion without end?); the game goes on";
      }
      case Hit::kMemory:
        return "stopped at " + std::to_string(env.budget_memory()) +
               " bytes of CLIPS memory, more than the memory budget of " +
               std::to_string(state.config.max_memory_bytes) +
               " bytes (max_memory_bytes; facts piling up?); the game goes on";
      case Hit::kWall:
        return "stopped after " + core::number_text(state.config.max_cycle_wall_s) +
               " s of wall time in one agent cycle (an endless loop in its actions?); the game "
               "goes on";
      default:
        return "stopped after " + std::to_string(state.config.max_steps_per_cycle) +
               " steps of work in one agent cycle (an endless loop in its actions?); the game "
               "goes on";
    }
  }

  void load(const std::string& text, std::string_view source) {
    std::string msg;
    for (const std::string& e : load_collect(text, source)) {
      if (!msg.empty()) msg += '\n';
      msg += e;
    }
    if (!msg.empty()) throw AgentLoadError(msg);
  }

  // Loads constructs; returns the errors as "source:LINE: message".
  std::vector<std::string> load_collect(const std::string& text, std::string_view source) {
    note_rule_places(text, source);
    const auto errors = env.load(text);
    flush_output();
    std::vector<std::string> out;
    if (errors.empty()) {
      // Loaded: what CLIPS takes without a word but that makes a rule misbehave.
      for (const SourceWarning& w : time_check.scan(text)) {
        emit(LogLevel::kWarn,
             std::string(source) + ":" + std::to_string(w.line) + ": " + w.message);
      }
      return out;
    }
    for (const auto& e : errors) {
      out.push_back(std::string(source) + ":" + std::to_string(e.line) + ": " +
                    with_hint(e.message));
    }
    return out;
  }

  void start(core::SimTime now) {
    state.now = now;
    env.reset();
    for (auto& f : features) f->after_reset(env);
    started = true;
    flush_output();
  }

  CycleResult cycle(core::SimTime now) {
    env.start_budget(state.config.max_steps_per_cycle, state.config.max_cycle_wall_s,
                     state.config.max_call_depth);
    if (!started) start(now);
    state.now = now;
    CycleResult result;
    const int errors_before = runtime_errors;
    for (auto& f : features) f->before_run(env);
    report_errors();  // e.g. a (test ...) that failed while facts were asserted

    run_rules(result);
    result.steps = env.budget_steps();
    max_steps_seen = std::max(max_steps_seen, result.steps);
    for (auto& f : features) f->after_run(env);
    flush_output();
    rules_fired += result.rules_fired;
    result.runtime_errors = runtime_errors - errors_before;
    if (tracer) tracer->cycle_end();
    return result;
  }

  // Runs to quiescence within the firing limit; an error stops CLIPS' run, so it is reported,
  // cleared, and the run goes on with the rest.
  void run_rules(CycleResult& result) {
    std::int64_t remaining = state.config.max_rules_per_cycle;
    while (remaining > 0) {
      const std::int64_t fired = env.run(remaining);
      result.rules_fired += fired;
      remaining -= fired;
      const bool error = env.halted() || !werror.empty();
      if (!error) break;
      if (env.budget_hit() != detail::Environment::BudgetHit::kNone) {
        // The rule's actions were stopped by the work budget: the cycle ends here.
        result.budget_exceeded = true;
        budget_reason = budget_text();
        if (werror.find("[PRCCODE4]") == std::string::npos) {
          werror +=
              "[PRCCODE4] Execution halted during the actions of defrule " + env.next_rule() + ".";
        }
        report_errors();
        env.clear_halt();
        break;
      }
      report_errors();
      env.clear_halt();
      if (env.agenda_empty()) break;
    }
    if (remaining <= 0 && !env.agenda_empty() && !result.budget_exceeded) {
      result.limit_reached = true;
      ++limit_hits;
      const std::string rule = env.next_rule();
      const std::string what = "rule firing limit of " +
                               std::to_string(state.config.max_rules_per_cycle) +
                               " reached with rules still on the agenda (endless rule loop?)";
      emit(LogLevel::kWarn, what + "; next: rule " + rule + place_of(rule_places, rule));
      issue(AgentIssueKind::kRuleLoop, rule, what);
    }
  }
};

AgentHost::AgentHost(AgentConfig config, AgentIo io)
    : impl_(std::make_unique<Impl>(std::move(config), std::move(io))) {}
AgentHost::~AgentHost() = default;
// The tracer's events point at the host: a move takes it along.
AgentHost::AgentHost(AgentHost&& other) noexcept : impl_(std::move(other.impl_)) {
  if (impl_ && impl_->tracer) impl_->tracer->set_host(*this);
}
AgentHost& AgentHost::operator=(AgentHost&& other) noexcept {
  impl_ = std::move(other.impl_);
  if (impl_ && impl_->tracer) impl_->tracer->set_host(*this);
  return *this;
}

void AgentHost::load_file(const std::string& path) {
  if (impl_->state.config.fawkes) return impl_->fawkes_start(path);
  std::string error;
  const auto text = core::try_read_input_file(path, core::kMaxSourceBytes, "CLIPS file", error);
  if (!text) throw AgentLoadError(error);
  impl_->load(*text, path);
}

void AgentHost::load_string(std::string_view code, std::string_view source_name) {
  impl_->load(std::string(code), source_name);
}

void AgentHost::start(core::SimTime now) { impl_->start(now); }

CycleResult AgentHost::cycle(core::SimTime now) { return impl_->cycle(now); }

void AgentHost::set_pose(const core::Pose2D& pose) {
  auto& s = impl_->state;
  if (s.pose && s.pose->x == pose.x && s.pose->y == pose.y && s.pose->theta == pose.theta) return;
  s.pose = pose;
  s.pose_dirty = true;
}

void AgentHost::write_interface(std::string_view type, std::string_view id,
                                InterfaceFields fields) {
  // (the key's strings reused: no allocation per write of an interface already there)
  auto& key = impl_->interface_key;
  key.first.assign(type);
  key.second.assign(id);
  auto it = impl_->state.blackboard.find(key);
  if (it == impl_->state.blackboard.end()) it = impl_->state.blackboard.try_emplace(key).first;
  auto& d = it->second;
  d.time = impl_->state.now;
  d.fields = std::move(fields);
  ++d.serial;
}

void AgentHost::receive(std::unique_ptr<google::protobuf::Message> message, std::string_view from,
                        int from_id, core::SimTime at) {
  if (!message) return;
  if (impl_->tracer) impl_->tracer->message_in(*message, from, at);
  impl_->state.inbox.push_back({std::move(message), std::string(from), from_id, at});
}

std::vector<Fact> AgentHost::facts(std::string_view template_name) const {
  std::vector<Fact> out;
  for (auto& f : impl_->env.facts(template_name))
    out.push_back(Fact{f.index, std::move(f.template_name), std::move(f.slots)});
  return out;
}

std::vector<Fact> AgentHost::find_facts(
    std::string_view template_name,
    std::initializer_list<std::pair<std::string_view, Value>> where) const {
  std::vector<Fact> out;
  for (auto& f : facts(template_name)) {
    bool match = true;
    for (const auto& [slot, value] : where) {
      if (!(f.slot(slot) == value)) {
        match = false;
        break;
      }
    }
    if (match) out.push_back(std::move(f));
  }
  return out;
}

void AgentHost::assert_fact(std::string_view fact) {
  const bool ok = impl_->env.assert_string(std::string(fact));
  if (!ok) {
    const std::string why = one_line(impl_->werror);
    impl_->werror.clear();
    impl_->env.clear_halt();
    throw std::invalid_argument("cannot assert " + std::string(fact) + ": " + why);
  }
  impl_->flush_output();
}

Value AgentHost::eval(std::string_view expression) {
  Value v = impl_->env.eval(std::string(expression));
  impl_->flush_output();
  impl_->env.clear_halt();
  return v;
}

void AgentHost::set_trace(TraceOptions options, TraceSink sink) {
  impl_->env.observe(nullptr, false, false);
  impl_->tracer.reset();
  if (!sink) return;
  impl_->tracer = std::make_unique<detail::Tracer>(impl_->state, *this, options, std::move(sink));
  impl_->env.observe(impl_->tracer.get(), options.rules, options.facts, options.fact_texts);
}

std::string AgentHost::fact_text(std::int64_t index) const { return impl_->env.fact_text(index); }

void AgentHost::fact_texts(std::vector<std::pair<std::int64_t, std::string>>& out,
                           std::int64_t from_index) const {
  impl_->env.fact_texts(out, from_index);
}

int AgentHost::runtime_errors() const { return impl_->runtime_errors; }
std::int64_t AgentHost::max_cycle_steps() const { return impl_->max_steps_seen; }
int AgentHost::limit_hits() const { return impl_->limit_hits; }
std::int64_t AgentHost::rules_fired() const { return impl_->rules_fired; }
int AgentHost::live_messages() const { return impl_->state.live_messages; }
const AgentConfig& AgentHost::config() const { return impl_->state.config; }

}  // namespace llsf::clips
