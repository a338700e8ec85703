// SPDX-License-Identifier: MIT
// `llsfsim run` (one game of a scenario, summary, test verdicts) and `llsfsim check` (validate a
// scenario with its agent and skill files without playing).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "cli_checks.h"
#include "commands.h"
#include "live.h"
#include "llsf/app/cli.h"
#include "llsf/clips/agent.h"
#include "llsf/clips/agent_files.h"
#include "llsf/clips/source_check.h"
#include "llsf/comm/socket_config.h"
#include "llsf/core/config.h"
#include "llsf/core/error.h"
#include "llsf/lua/skill_doc.h"
#include "llsf/sim/agent_brain.h"
#include "llsf/study/metrics.h"
#include "llsf/study/player.h"
#include "llsf/study/recording.h"
#include "llsf/study/runner.h"
#include "llsf/study/scenario.h"
#include "llsf/study/stats_store.h"
#include "refbox_sockets.h"
#include "server.h"

namespace llsf::app {

namespace {

struct RunOptions {
  std::string scenario;
  std::optional<std::uint64_t> seed;
  std::string variant;
  bool json = false;
  bool quiet = false;
  std::string db{study::StatsStore::kDefaultPath};
  bool no_db = false;
  std::string record;  ///< "" = default_recordings_dir(db)/recording_file_name(...)
  bool no_record = false;
  bool no_reload = false;          // paced runs: do not reload changed CLIPS files
  bool strict = false;             ///< an agent mistake (RunIssue::is_mistake) fails the run
  bool fail_fast = false;          ///< stop the game at the first agent error
  std::vector<std::string> trace;  ///< --trace ROBOT[:KINDS], repeatable
  std::string trace_file;          ///< "" = stderr
  bool no_record_agents = false;   ///< no facts/fact/rules lines in the recording
  LiveOptions live;                ///< --speed, --realtime, --serve, --port, --serve-exit
  bool refbox_sockets = false;     ///< --refbox-sockets given
  std::string sockets_file;        ///< its SOCKETS.yaml ("" = the defaults)
};

/// Why a file cannot be created or replaced at `path` ("" if it can): checked before a game, so
/// that a recording that cannot be written costs no game.
std::string cannot_create(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : ".";
  if (!fs::is_directory(dir, ec)) return "the folder " + dir.string() + " does not exist";
  if (fs::is_directory(path, ec)) return "it is a directory";
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    return "the folder " + dir.string() +
           " is not writable: " + std::error_code(errno, std::generic_category()).message();
  }
  if (fs::exists(path, ec) && ::access(path.c_str(), W_OK) != 0) {
    return "the file is not writable: " + std::error_code(errno, std::generic_category()).message();
  }
  return "";
}

const study::Scenario* pick_variant(const study::ScenarioFile& f, const std::string& name,
                                    std::ostream& err) {
  if (name.empty()) return &f.variants.front();
  for (const study::Scenario& s : f.variants) {
    if (s.variant == name) return &s;
  }
  // A variant may also be named by its values only ("P3-P3" for "config=P3-P3").
  for (const study::Scenario& s : f.variants) {
    const auto eq = s.variant.find('=');
    if (eq != std::string::npos && s.variant.find(',') == std::string::npos &&
        s.variant.substr(eq + 1) == name) {
      return &s;
    }
  }
  if (f.variants.size() == 1 && f.variants.front().variant.empty()) {
    err << "llsfsim run: " << f.file << " has no matrix, so no variant '" << name
        << "': play it without --variant (variants come from a scenario's `matrix`, "
           "docs/scenarios.md)\n";
    return nullptr;
  }
  err << "llsfsim run: " << f.file << " has no variant '" << name << "'; its variants:\n";
  for (const study::Scenario& s : f.variants) err << "  " << s.variant << "\n";
  return nullptr;
}

/// The run's issues: the mistakes (runtime errors, rule loops, long lock holds) each on a line
/// with time, robot, rule and file:line (at most 10), then the skill failures grouped by robot,
/// skill and error (docs/llsfsim.md, "Issues").
void print_issues(const study::RunResult& r, std::ostream& out) {
  int mistakes = 0;
  int halted_late = 0;  // agent-halted issues shown after the first 10
  std::map<std::string, std::pair<int, double>> failures;  // "robot skill: error" -> (n, first)
  for (const study::RunIssue& i : r.issues) {
    if (!i.is_mistake()) {
      const std::string skill = i.skill.substr(0, i.skill.find('{'));
      const std::string& error = i.text;
      // (the engine's error starts with the skill's name already: named once)
      const bool named = error.compare(0, skill.size() + 2, skill + ": ") == 0;
      auto& f = failures[i.robot + " " + (named ? error : skill + ": " + error)];
      if (f.first++ == 0) f.second = i.time_s;
      continue;
    }
    // The first 10, and every agent-halted one (it says why the agent stopped playing).
    if (mistakes++ >= 10 && i.kind != study::IssueKind::kAgentHalted) continue;
    if (mistakes > 10) ++halted_late;
    std::string where;
    if (!i.rule.empty()) where = " rule " + i.rule;
    if (!i.file.empty()) where += " (" + i.place() + ")";
    // An unknown skill: its skill string before the engine's error.
    const std::string text = i.skill.empty() ? i.text : i.skill + ": " + i.text;
    out << fmt::format("issue      {:7.1f} s {} {}{}: {}\n", i.time_s, i.robot,
                       study::to_string(i.kind), where, text);
  }
  // r.mistakes counts those not kept too (RunResult::kMaxIssues).
  const int shown_mistakes = std::min(mistakes, 10) + halted_late;
  if (r.mistakes > shown_mistakes) {
    out << fmt::format(
        "issue      ... and {} more mistakes, {} in all (--json lists the first {} "
        "issues)\n",
        r.mistakes - shown_mistakes, r.mistakes, study::RunResult::kMaxIssues);
  }
  int shown = 0;
  for (const auto& [what, f] : failures) {
    if (shown++ >= 10) {
      out << fmt::format("skills     ... and {} more kinds of failure (--json)\n",
                         failures.size() - 10);
      break;
    }
    out << fmt::format("skills     {}x {} (first at {:.1f} s)\n", f.first, what, f.second);
  }
  if (r.issues_dropped > 0) {
    out << fmt::format("issue      {} more issues not kept (the first {} are)\n", r.issues_dropped,
                       study::RunResult::kMaxIssues);
  }
}

}  // namespace

void print_summary(const study::RunResult& r, std::ostream& out) {
  out << fmt::format("scenario   {}{}  seed {}\n", r.scenario,
                     r.variant.empty() ? "" : " [" + r.variant + "]", r.seed);
  // The metrics' lines, as the metric table says (study/metrics.h): each metric's part in table
  // order on its line; between them what is no metric (the orders, the issues, the hash).
  using Show = study::SummaryLine::Show;
  for (const study::SummaryLine& line : study::summary_lines()) {
    std::string text;
    bool nonzero = false;
    std::vector<const study::Metric*> parts;
    for (const study::Metric& m : study::metrics()) {
      if (m.line == line.label) parts.push_back(&m);
    }
    std::stable_sort(parts.begin(), parts.end(),
                     [](const study::Metric* a, const study::Metric* b) {
                       return a->summary_rank < b->summary_rank;
                     });
    for (const study::Metric* part : parts) {
      const study::Metric& m = *part;
      const std::optional<double> v = m.value(r);
      if (v && *v != 0.0 && m.json_form != study::JsonForm::kBool) nonzero = true;
      if (!v) {
        text += m.summary_absent;
      } else if (m.json_form == study::JsonForm::kBool) {
        text += fmt::format(fmt::runtime(m.summary), *v != 0.0 ? "yes" : "no");
      } else {
        text += fmt::format(fmt::runtime(m.summary), *v);
      }
    }
    if (line.show == Show::kIfAnyNonZero && !nonzero) continue;
    if (line.show == Show::kIfProfile) {
      if (r.profile == "ideal" && r.jams == 0) continue;
      text = r.profile + ": " + text;
    }
    out << fmt::format("{:<11}{}\n", line.label, text);
    if (line.label == "orders") {
      for (const study::OrderResult& o : r.orders) {
        out << fmt::format("           #{} {} {}/{} [{}-{} s]\n", o.id, o.product, o.delivered,
                           o.requested, o.window_begin_s, o.window_end_s);
      }
    } else if (line.label == "robots") {
      print_issues(r, out);
    } else if (line.label == "speed") {
      out << fmt::format("result     {:016x}\n", r.result_hash);
    } else if (line.label == "tests") {
      for (const study::TestVerdict& t : r.tests) {
        out << fmt::format("test       {}  {}: {}\n", t.passed ? "PASS" : "FAIL", t.name, t.detail);
      }
    }
  }
}

namespace {

/// Prints the agent warnings `run` shows before its game (a confval nobody reads, a time read
/// CLIPS never evaluates again, the sandbox
/// off; `check` has them all), each once, on `err`.
void print_run_warnings(const study::Scenario& s, std::ostream& err);

int run(const RunOptions& o, std::ostream& out, std::ostream& err) {
  study::ScenarioFile file;
  try {
    file = study::load_scenario(o.scenario);
  } catch (const core::ConfigError& e) {
    err << "llsfsim run: " << e.what() << "\n";
    return kExitBadInput;
  }
  const study::Scenario* s = pick_variant(file, o.variant, err);
  if (s == nullptr) return kExitBadInput;
  const std::uint64_t seed = o.seed.value_or(s->seeds.front());
  if (!o.quiet) print_run_warnings(*s, err);
  // The statistics store is opened before playing so that a bad path costs no game.
  std::optional<study::StatsStore> store;
  study::BatchKey key;
  if (!o.no_db) {
    try {
      store.emplace(o.db);
      store->require_writable();
      key.kind = study::BatchKey::Kind::kRun;
      key.scenario_file = o.scenario;
      key.scenario_name = s->name;
      key.scenario_hash = study::batch_identity_hash(o.scenario, file);
      key.variants = static_cast<int>(file.variants.size());
      key.seeds = s->seeds;
    } catch (const study::StatsError& e) {
      err << "llsfsim run: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  // --refbox-sockets: the config read and every socket bound before anything is played or
  // written; the UDP peers become radio peers of the game.
  std::unique_ptr<RefboxSockets> sockets;
  study::Scenario played = *s;
  played.strict = played.strict || o.strict;
  if (o.refbox_sockets) {
    try {
      comm::SocketConfig sc;
      if (!o.sockets_file.empty()) {
        sc = comm::load_socket_config(core::ConfigNode::load_file(o.sockets_file));
      }
      sockets = std::make_unique<RefboxSockets>(sc, played.game.hub.lock_messages,
                                                [&err](std::string_view line) {
                                                  err << "llsfsim run: " << line << "\n";
                                                  err.flush();
                                                });
      played.game.external_peers = sockets->external_peers();
      played.game.validate();
    } catch (const core::UserError& e) {
      // The game names its external peers by the sockets file's udp_peers, in the same order.
      std::string what = e.what();
      const std::string field = "game.external_peers[";
      if (what.starts_with(field)) what = "udp_peers[" + what.substr(field.size());
      err << "llsfsim run: --refbox-sockets"
          << (o.sockets_file.empty() ? std::string() : " " + o.sockets_file) << ": " << what
          << "\n";
      return kExitBadInput;
    }
  }
  study::RunHooks hooks;
  // --trace: checked before anything is played or written.
  std::unique_ptr<std::ofstream> trace_file;
  try {
    for (const std::string& t : o.trace) hooks.trace.push_back(study::parse_trace_request(t));
    study::check_trace_requests(*s, hooks.trace);
  } catch (const core::UserError& e) {
    err << "llsfsim run: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (!hooks.trace.empty()) {
    if (!o.trace_file.empty()) {
      trace_file = std::make_unique<std::ofstream>(o.trace_file, std::ios::binary);
      if (!*trace_file) {
        err << "llsfsim run: --trace-file " << o.trace_file << ": cannot write the file\n";
        return kExitBadInput;
      }
    }
    std::ostream* trace_out = trace_file ? trace_file.get() : &err;
    hooks.trace_sink = [trace_out](std::string_view line) { *trace_out << line << '\n'; };
  }
  hooks.record_agents = !o.no_record_agents;
  hooks.stop_at_agent_error = o.fail_fast;
  if (!o.no_record) {
    hooks.record_path = o.record;
    if (hooks.record_path.empty()) {
      const std::filesystem::path dir = default_recordings_dir(o.db);
      std::error_code ec;
      std::filesystem::create_directories(dir, ec);
      if (ec) {
        err << "llsfsim run: cannot create the recordings directory " << dir.string() << ": "
            << ec.message() << "\n";
        return kExitBadInput;
      }
      hooks.record_path = (dir / study::recording_file_name(s->name, s->variant, seed)).string();
    }
    if (const std::string why = cannot_create(hooks.record_path); !why.empty()) {
      err << "llsfsim run: " << hooks.record_path << ": cannot create the recording: " << why
          << "\n";
      return kExitBadInput;
    }
  }
  // Paced mode: sleep between ticks so that game time runs `speed` times as fast as the wall
  // clock (the wall clock only paces; it never enters the game).
  if (o.live.pace() > 0.0) {
    if (sockets) {
      // Served: the tick's messages go out, then the pause, then what arrived goes in (for the
      // next tick). Socket I/O happens only here, between ticks, on the game's thread.
      hooks.attach = [&sockets](sim::Game& g) { sockets->attach(g); };
      hooks.tick = [pacer = Pacer(o.live.pace()), &sockets](const sim::Game& g) {
        sockets->send_tick();
        pacer.wait(g.time().seconds());
        sockets->receive();
      };
    } else {
      hooks.tick = [pacer = Pacer(o.live.pace())](const sim::Game& g) {
        pacer.wait(g.time().seconds());
      };
    }
    // Live editing: changed CLIPS files are reloaded (docs/llsfsim.md, "Editing while it plays").
    hooks.reload_agents = !o.no_reload;
    hooks.note = [&err](core::SimTime t, const std::string& robot, const std::string& text) {
      err << fmt::format("[{:.1f} s] {}: {}\n", t.seconds(), robot, text);
      err.flush();
    };
  }
  // --serve: the viewer's server on a background thread, fed every recording line.
  std::ostream& note = o.json ? err : out;  // keep --json's stdout one JSON object
  LiveFeed feed;
  std::unique_ptr<Server> server;
  try {
    ServerOptions so;
    so.db = o.no_db ? "" : o.db;
    so.recordings = default_recordings_dir(o.db);
    server = start_live_server(o.live, so, feed, note);
  } catch (const core::UserError& e) {  // cannot listen
    err << "llsfsim run: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (server) hooks.record_sink = [&feed](std::string_view line) { feed.publish(line); };
  if (sockets) {
    for (const std::string& line : sockets->describe()) {
      note << "llsfsim run: refbox sockets: " << line << "\n";
    }
    note.flush();
  }
  // (No progress line between trace lines on stderr.)
  const bool tty = isatty(STDERR_FILENO) != 0 && !o.quiet && !o.json &&
                   (hooks.trace.empty() || trace_file != nullptr);
  if (tty) {
    hooks.progress_every = core::SimTime::from_sec(10);
    hooks.progress = [&](const sim::Game& g) {
      std::fprintf(stderr, "\r[%5.0f/%.0f s] %s, %d points", g.time().seconds(),
                   s->duration.seconds(), refbox::to_string(g.refbox().phase()).data(),
                   g.refbox().points());
      std::fflush(stderr);
    };
  }
  study::RunResult r;
  try {
    r = study::run_game(played, seed, hooks);
  } catch (const clips::AgentLoadError& e) {
    err << "llsfsim run: agent error:\n" << e.what() << "\n";
    return kExitBadInput;
  } catch (const core::ConfigError& e) {
    err << "llsfsim run: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const core::UserError& e) {  // e.g. the recording cannot be written
    err << "llsfsim run: " << e.what() << "\n";
    return kExitBadInput;
  }
  feed.finish();
  if (tty) std::fprintf(stderr, "\r%60s\r", "");
  std::string stored_as;
  if (store) {
    try {
      const std::int64_t batch = store->open_batch(key);
      const std::int64_t run = store->add_run(batch, r, /*replace=*/true);
      stored_as = fmt::format("{} (batch {}, run {})", store->path(), batch, run);
    } catch (const study::StatsError& e) {
      err << "llsfsim run: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  if (o.json) {
    out << study::to_json(r) << "\n";
  } else if (!o.quiet) {
    print_summary(r, out);
    if (!r.recording.empty()) out << fmt::format("recording  {}\n", r.recording);
    if (!stored_as.empty()) out << fmt::format("database   {}\n", stored_as);
  }
  serve_until_stopped(o.live, server, note);
  return r.passed() ? kExitOk : kExitFailed;
}

/// One of `check`'s findings about an agent.
struct AgentWarning {
  enum class Kind { kWarn, kNote };
  Kind kind = Kind::kWarn;
  bool in_run = false;  ///< `run` prints it too (before the game, on stderr)
  std::string text;
  bool operator<(const AgentWarning& o) const { return text < o.text; }
};

/// `check`'s warnings about one robot's agent (docs/llsfsim.md, `check`): the static checks of
/// its files (clips::check_agent: time reads, skill calls against the skill library with
/// `brain` only, confvals against robots.config, the lock switch), then the sandbox switched
/// off. Those marked in_run `run` prints too.
std::vector<AgentWarning> agent_warnings(const study::RobotSpec& spec,
                                         const sim::AgentBrain* brain) {
  // A Fawkes-style agent's files in the order its entry file path-loads them (a deffunction
  // that reads the time counts in the files loaded after its own).
  const std::vector<clips::SourceFile> sources =
      spec.fawkes && !spec.agent.empty()
          ? clips::read_fawkes_sources(spec.agent_dir, spec.agent.front())
          : clips::read_agent_sources(spec.agent);
  clips::AgentCheckFacts facts;
  if (brain != nullptr) {
    facts.skills.emplace();
    for (const lua::SkillInfo& s : brain->skills().engine().skills()) {
      facts.skills->push_back({s.name, lua::documented_params(s.documentation)});
    }
  }
  facts.config = spec.config;
  facts.locks = spec.locks;
  facts.fawkes = spec.fawkes;
  std::vector<AgentWarning> warnings;
  for (clips::AgentFinding& f : clips::check_agent(sources, facts)) {
    using Kind = clips::AgentFinding::Kind;
    const bool in_run = f.kind == Kind::kTimeRead || f.kind == Kind::kConfvalNotRead;
    warnings.push_back(
        {f.note ? AgentWarning::Kind::kNote : AgentWarning::Kind::kWarn, in_run, f.text()});
  }
  if (!spec.sandbox) {
    warnings.push_back({AgentWarning::Kind::kNote, /*in_run=*/true,
                        "robots.sandbox is off: the agent may open, load and write files and run "
                        "programs (docs/security.md); only for a trusted local agent"});
  }
  return warnings;
}

void print_run_warnings(const study::Scenario& s, std::ostream& err) {
  std::set<AgentWarning> shown;
  for (const study::RobotSpec& spec : s.robots) {
    if (spec.agent.empty()) continue;
    for (AgentWarning& w : agent_warnings(spec, nullptr)) {
      if (!w.in_run || !shown.insert(w).second) continue;
      err << "llsfsim run: " << (w.kind == AgentWarning::Kind::kNote ? "note: " : "warn: ")
          << w.text << "\n";
    }
  }
}

int check(const std::vector<std::string>& files, std::ostream& out, std::ostream& err) {
  int bad = 0;
  for (const std::string& path : files) {
    try {
      const study::ScenarioFile f = study::load_scenario(path);
      std::size_t seeds = 0;
      std::set<std::string> warned;  // each warning once per file
      for (const study::Scenario& s : f.variants) {
        seeds += s.seeds.size();
        // Build the game and every brain: agent files are parsed, skill files loaded.
        study::Player player(s, s.game.seed);
        for (int i = 0; i < player.game().robot_count(); ++i) {
          const study::RobotSpec& spec = s.robots.at(static_cast<std::size_t>(i));
          const sim::AgentBrain* plugged = player.plug_agent(i);
          if (plugged == nullptr) continue;
          const sim::AgentBrain& brain = *plugged;
          for (const std::string& e : brain.skills().engine().load_errors()) {
            throw core::ConfigError("skill file error: " + e);
          }
          for (const AgentWarning& w : agent_warnings(spec, &brain)) {
            if (!warned.insert(w.text).second) continue;
            out << (w.kind == AgentWarning::Kind::kNote ? "note " : "warn ") << path << ": "
                << w.text << "\n";
          }
        }
      }
      out << fmt::format("ok   {}: {} variant(s), {} game(s)\n", path, f.variants.size(), seeds);
    } catch (const core::UserError& e) {  // anything else is a bug: exit code 3 (cli.cpp)
      err << "FAIL " << path << ": " << e.what() << "\n";
      ++bad;
    }
  }
  return bad == 0 ? kExitOk : kExitBadInput;
}

}  // namespace

Action add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  app.add_option("scenario", o->scenario, "Scenario file (docs/scenarios.md)")->required();
  app.add_option("--seed", o->seed, "Seed to play (default: the scenario's first)")->check(kSeed);
  app.add_option("--variant", o->variant,
                 "Matrix variant, e.g. 'config=P3-P3' or just 'P3-P3' (default: the first)");
  app.add_flag("--json", o->json, "Print the summary as one JSON object");
  app.add_flag("-q,--quiet", o->quiet, "No summary, only the exit code");
  app.add_flag("--strict", o->strict,
               "Fail the run (exit 1) on any agent mistake: a runtime error (also a rule stopped "
               "by the work budget), a rule loop cut by the firing limit, a lock held over 300 s, "
               "an unknown skill (as the scenario key strict: true)");
  app.add_flag("--fail-fast", o->fail_fast,
               "Stop the game at the first agent error (a runtime error or a halted agent); the "
               "run fails (exit 1)");
  auto* db = app.add_option("--db", o->db,
                            "Statistics store the run is written to: a SQLite file or a "
                            "postgresql://USER@HOST:PORT/DB URL (docs/statistics.md)")
                 ->capture_default_str();
  app.add_flag("--no-db", o->no_db, "Do not write the run to a statistics store")->excludes(db);
  auto* record =
      app.add_option("--record", o->record,
                     "Write the recording to FILE (gzip JSON lines, docs/recording.md; default: "
                     "llsfsim-recordings/<scenario>[-<variant>]-seed<N>.jsonl.gz, beside the --db "
                     "file and named after it; for a URL <database>-recordings/ in the working "
                     "directory)");
  app.add_flag("--no-record", o->no_record, "Do not record the game")->excludes(record);
  app.add_flag("--no-reload", o->no_reload,
               "Paced runs: do not reload the agent's CLIPS files when they change");
  app.add_flag("--no-record-agents", o->no_record_agents,
               "Record the game without the agents' facts and rule firings (the facts, fact and "
               "rules lines of docs/recording.md)");
  auto* trace =
      app.add_option(
             "--trace", o->trace,
             "Trace an agent: ROBOT[:KINDS] (repeatable; ROBOT a robot's name or all; KINDS "
             "a comma list of rules,facts,skills,msgs,log, default all). Prints rule firings "
             "with the facts that matched, fact assertions and retractions, skill calls and "
             "results, messages and log lines with simulated time stamps to stderr "
             "(docs/clips.md, \"Tracing\")")
          ->type_name("ROBOT[:KINDS]");
  app.add_option("--trace-file", o->trace_file, "Write the --trace lines to FILE, not stderr")
      ->type_name("FILE")
      ->needs(trace);
  add_live_options(app, o->live,
                   "Serve the browser viewer with this game live (like `llsfsim serve`; best with "
                   "--speed or --realtime)");
  auto* sockets_opt =
      app.add_option("--refbox-sockets", o->sockets_file,
                     "Serve the simulated refbox on sockets as the 2013 refbox does: controllers "
                     "(llsf-refbox-shell, ...) on TCP 127.0.0.1:4444, UDP peers as in SOCKETS.yaml "
                     "(docs/refbox-protocol.md, \"Attaching 2013 tools\"); times on the wire are "
                     "Unix time. Paced: implies --realtime unless --speed is given")
          ->type_name("[SOCKETS.yaml]")
          ->expected(0, 1);
  app.footer(
      "Plays one game headless and prints a summary and the test-case verdicts; stores the run "
      "in the statistics store (--db, default llsfsim.db; the latest game of each variant and "
      "seed of a scenario file's content) and writes a recording of it.\n"
      "Exit code: 0 all test cases passed, 1 one failed (or, with --strict, an agent made a "
      "mistake), 2 bad input (scenario, agent, skill "
      "file, a path that cannot be written, a --refbox-sockets file or a port that cannot be "
      "bound), 3 internal error (a bug: please report it).");
  return [o, sockets_opt](std::ostream& out, std::ostream& err) {
    o->refbox_sockets = sockets_opt->count() > 0;
    if (o->refbox_sockets && o->live.speed <= 0.0) o->live.realtime = true;
    return run(*o, out, err);
  };
}

Action add_check_command(CLI::App& app) {
  auto files = std::make_shared<std::vector<std::string>>();
  app.add_option("scenarios", *files, "Scenario files")->required();
  app.footer(
      "Validates scenarios: every key and value, every matrix variant, the agent files (CLIPS "
      "syntax) and the skill files, without playing.\n"
      "Exit code: 0 all valid, 2 one is not, 3 internal error (a bug: please report it).");
  return [files](std::ostream& out, std::ostream& err) { return check(*files, out, err); };
}

}  // namespace llsf::app
