// SPDX-License-Identifier: MIT
// The subcommands of llsfsim: each registers its options on a CLI11 subcommand and runs.
#pragma once

#include <CLI/CLI.hpp>

#include <cctype>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>

#include "llsf/study/stats_store.h"

namespace llsf::app {

/// A subcommand's action, called after parsing; returns the exit code.
using Action = std::function<int(std::ostream& out, std::ostream& err)>;

/// Where recordings go by default: "<name>-recordings" beside the statistics store `db`
/// (llsfsim.db: llsfsim-recordings/), so that two stores never share one; for a database server
/// (`postgresql://.../study`) "<database>-recordings" in the working directory (study-recordings/,
/// llsfsim-recordings/ when the URL names no database).
inline std::string default_recordings_dir(const std::string& db) {
  if (study::is_database_url(db)) {
    const std::size_t authority = db.find("://") + 3;
    const std::size_t slash = db.find('/', authority);
    std::string name =
        slash == std::string::npos ? "" : db.substr(slash + 1, db.find('?', slash) - slash - 1);
    for (char& c : name) {
      if (std::isalnum(static_cast<unsigned char>(c)) == 0 && c != '-' && c != '_') c = '_';
    }
    return (name.empty() ? std::string("llsfsim") : name) + "-recordings";
  }
  const std::filesystem::path p(db);
  return (p.parent_path() / (p.stem().string() + "-recordings")).string();
}

/// The summary of a run as `llsfsim run` prints it (docs/llsfsim.md): the metrics' lines as the
/// metric table says (study/metrics.h), with the orders, the issues, the result hash and the
/// test verdicts.
void print_summary(const study::RunResult& r, std::ostream& out);

/// `llsfsim skill`: one skill string (or several, in turn) on one robot in a fresh game.
Action add_skill_command(CLI::App& app);
/// `llsfsim run`: one game of a scenario with a summary and the test-case verdicts.
Action add_run_command(CLI::App& app);
/// `llsfsim batch`: every variant x N seeds on worker threads, stored in the statistics store.
Action add_batch_command(CLI::App& app);
/// `llsfsim experiment`: an experiment's batches played, its findings checked and reported.
Action add_experiment_command(CLI::App& app);
/// `llsfsim report`: statistics of a stored batch, differences between variants, CSV.
Action add_report_command(CLI::App& app);
/// `llsfsim check`: validate scenarios and their agent/skill files without playing.
Action add_check_command(CLI::App& app);
/// `llsfsim exercise`: a hackathon exercise (exercises/) played with the participant's skill.
Action add_exercise_command(CLI::App& app);
/// `llsfsim test-agent`: rule tests of CLIPS agents from YAML files (docs/agent-tests.md).
Action add_test_agent_command(CLI::App& app);
/// `llsfsim new agent`: a minimal working two-robot agent with a scenario and a rule test.
Action add_new_command(CLI::App& app);
/// `llsfsim field-map`: the field as an SVG with coordinates (or Markdown tables), from the config.
Action add_field_map_command(CLI::App& app);
/// `llsfsim serve`: the browser viewer's HTTP/WebSocket server (server.h) until SIGINT/SIGTERM.
Action add_serve_command(CLI::App& app);
/// `llsfsim hackathon serve`: the hackathon leaderboard (hackathon.h) until SIGINT/SIGTERM.
Action add_hackathon_command(CLI::App& app);

}  // namespace llsf::app
