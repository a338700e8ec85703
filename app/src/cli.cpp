// SPDX-License-Identifier: MIT
#include "llsf/app/cli.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <exception>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "llsf/core/error.h"
#include "llsf/core/text.h"
#include "llsf/core/version.h"

namespace llsf::app {

namespace {

/// An exception that is not the user's error: a bug. Says so and how to report it; exit code 3.
int internal_error(const std::string& who, const char* what, std::ostream& err) {
  err << who << ": internal error: " << what << "\n"
      << "This is a bug in llsfsim " << core::kVersion
      << "; please report it with the command line and the scenario file.\n";
  return kExitInternalError;
}

/// The candidate `name` is a likely typo of: core::closest_match, or one with two neighbouring
/// characters swapped (`rnu` for `run`, too far for a third of three letters).
std::optional<std::string> likely_meant(const std::string& name,
                                        const std::vector<std::string>& candidates) {
  if (auto m = core::closest_match(name, candidates)) return m;
  for (const std::string& c : candidates) {
    if (c.size() != name.size()) continue;
    for (std::size_t i = 0; i + 1 < c.size(); ++i) {
      std::string swapped = name;
      std::swap(swapped[i], swapped[i + 1]);
      if (swapped == c) return c;
    }
  }
  return std::nullopt;
}

/// What the command line names that `app` does not know, with a did-you-mean: an unknown
/// command (`llsfsim rnu`) or long option (`--verison`) of the innermost command parsed. Empty
/// if every name is known (the parse error is about something else).
std::string unknown_name(const CLI::App& app, std::span<const std::string> args) {
  const CLI::App* ctx = &app;
  std::string who = "llsfsim";
  while (!ctx->get_subcommands().empty()) {
    ctx = ctx->get_subcommands().front();
    who += " " + ctx->get_name();
  }
  std::vector<std::string> commands;
  for (const CLI::App* sub : ctx->get_subcommands({})) commands.push_back(sub->get_name());
  std::vector<std::string> options;
  bool takes_words = false;  // a positional (`batch SCENARIO...`): any word may be its value
  for (const CLI::Option* o : ctx->get_options()) {
    for (const std::string& l : o->get_lnames()) options.push_back("--" + l);
    takes_words = takes_words || o->get_positional();
  }
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--") break;
    if (a.rfind("--", 0) == 0 && a.size() > 2) {
      const std::string name = a.substr(0, a.find('='));
      if (std::find(options.begin(), options.end(), name) != options.end()) continue;
      // An option of an outer command (`--help`, `--version`) is not a typo either.
      bool outer = false;
      for (const CLI::App* p = ctx->get_parent(); p != nullptr && !outer; p = p->get_parent()) {
        for (const CLI::Option* o : p->get_options())
          outer = outer || o->check_lname(name.substr(2));
      }
      if (outer) continue;
      std::string text = who + ": unknown option " + name;
      if (auto m = likely_meant(name, options)) text += "; did you mean " + *m + "?";
      return text;
    }
  }
  // The first word after the command chain where a command is expected: a command name.
  if (!commands.empty() && !takes_words && ctx->get_subcommands().empty()) {
    std::size_t i = 1;
    for (const CLI::App* p = ctx; p->get_parent() != nullptr; p = p->get_parent()) ++i;
    if (i < args.size() && args[i].rfind('-', 0) != 0 &&
        std::find(commands.begin(), commands.end(), args[i]) == commands.end()) {
      std::string text = who + ": unknown command '" + args[i] + "'";
      if (auto m = likely_meant(args[i], commands)) text += "; did you mean '" + *m + "'?";
      return text;
    }
  }
  return "";
}

}  // namespace

int run(std::span<const std::string> args, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "llsfsim: a fast, deterministic simulator of the RoboCup Logistics League 2013 (LLSF).\n"
      "Exit codes: 0 ok, 1 a skill or test case failed, 2 bad input, 3 internal error (a bug: "
      "please report it).",
      "llsfsim"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "llsfsim " + std::string(core::kVersion));
  std::vector<std::pair<CLI::App*, Action>> commands;
  {
    CLI::App* sub = app.add_subcommand("run", "Play one game of a scenario; print a summary");
    commands.emplace_back(sub, add_run_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "batch", "Play every variant x N seeds on worker threads; store and summarize the runs");
    commands.emplace_back(sub, add_batch_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "report", "Statistics of a stored batch per variant and differences between variants");
    commands.emplace_back(sub, add_report_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "experiment",
        "Play an experiment's batches; check its targets and findings; report the verdicts");
    commands.emplace_back(sub, add_experiment_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "check", "Validate scenarios and their agent and skill files without playing");
    commands.emplace_back(sub, add_check_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "test-agent", "Run rule tests of CLIPS agents (YAML files) without the world");
    commands.emplace_back(sub, add_test_agent_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "new", "Write a starting point: `new agent DIR` (agent, scenario, test)");
    commands.emplace_back(sub, add_new_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "skill", "Run skill strings on one robot in a fresh game; print status changes");
    commands.emplace_back(sub, add_skill_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "exercise", "Play a hackathon exercise with your skill; print progress, score, PASS/FAIL");
    commands.emplace_back(sub, add_exercise_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "field-map", "Draw the field with coordinates, machines, places and obstacles (SVG)");
    commands.emplace_back(sub, add_field_map_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "serve", "Serve the browser viewer, stored batches and recordings over HTTP");
    commands.emplace_back(sub, add_serve_command(*sub));
  }
  {
    CLI::App* sub = app.add_subcommand(
        "hackathon", "`hackathon serve`: the leaderboard where teams submit exercise skills");
    commands.emplace_back(sub, add_hackathon_command(*sub));
  }
  std::vector<std::string> argv_rest(args.begin() + (args.empty() ? 0 : 1), args.end());
  std::reverse(argv_rest.begin(), argv_rest.end());  // CLI11 parses a reversed vector
  try {
    app.parse(argv_rest);
  } catch (const CLI::CallForHelp&) {
    out << app.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::CallForVersion&) {
    out << app.version() << "\n";
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    if (const std::string unknown = unknown_name(app, args); !unknown.empty()) {
      err << unknown << "\n";
    } else {
      err << "llsfsim: " << e.what() << "\n";
    }
    // `run --refbox-sockets SCENARIO`: the optional value took the scenario.
    if (const CLI::App* r = app.get_subcommand("run"); r->parsed()) {
      const CLI::Option* scenario = r->get_option("scenario");
      const CLI::Option* sockets = r->get_option("--refbox-sockets");
      if (scenario->count() == 0 && sockets->count() > 0 && !sockets->results().empty() &&
          !sockets->results().front().empty()) {
        const std::string taken = sockets->results().front();
        err << "hint: --refbox-sockets took '" << taken
            << "' as its sockets file (its value is optional): put it after the scenario, "
               "llsfsim run "
            << taken << " --refbox-sockets\n";
      }
    }
    if (app.get_subcommands().empty()) {
      err << "Run 'llsfsim --help' for the commands.\n";
    } else {
      err << "Run 'llsfsim " << app.get_subcommands().front()->get_name()
          << " --help' for its options.\n";
    }
    return kExitBadInput;
  } catch (const std::exception& e) {
    return internal_error("llsfsim", e.what(), err);
  }
  // The commands catch what they can say more about; the user's errors left over exit with 2,
  // anything else is a bug (exit code 3).
  for (auto& [sub, action] : commands) {
    if (!sub->parsed()) continue;
    const std::string who = "llsfsim " + sub->get_name();
    try {
      return action(out, err);
    } catch (const core::UserError& e) {
      err << who << ": " << e.what() << "\n";
      return kExitBadInput;
    } catch (const std::exception& e) {
      return internal_error(who, e.what(), err);
    } catch (...) {
      return internal_error(who, "an exception of unknown type", err);
    }
  }
  return kExitBadInput;
}

}  // namespace llsf::app
