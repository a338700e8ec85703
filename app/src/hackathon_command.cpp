// SPDX-License-Identifier: MIT
// `llsfsim hackathon serve`: the leaderboard of a hackathon evening (hackathon.h,
// docs/hackathon-server.md) until SIGINT or SIGTERM.
#include <memory>
#include <ostream>
#include <string>

#include "commands.h"
#include "hackathon.h"
#include "llsf/app/cli.h"
#include "llsf/core/error.h"
#include "llsf/study/stats_store.h"
#include "server.h"

namespace llsf::app {

Action add_hackathon_command(CLI::App& app) {
  app.require_subcommand(1);
  CLI::App& serve = *app.add_subcommand(
      "serve", "Serve the leaderboard: teams submit skills, hidden seeds rank them");
  auto o = std::make_shared<HackathonOptions>();
  o->db = std::string(study::StatsStore::kDefaultPath);
  serve
      .add_option("--host", o->bind,
                  "Address to listen on: 127.0.0.1 (this machine only), the LAN address of this "
                  "machine, or 0.0.0.0 (every address) for a room of laptops")
      ->capture_default_str();
  serve.add_option("--port", o->port, "Port to listen on (0: any free port)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  serve
      .add_option("--db", o->db,
                  "SQLite file of the submissions (tables hackathon_*, beside the statistics "
                  "store's); kept across restarts")
      ->capture_default_str();
  serve
      .add_option("--seeds", o->seeds,
                  "Hidden seeds every submission is played on (like batch's --seeds: 1001-1005, "
                  "3,5,9-12); never shown to teams")
      ->capture_default_str();
  serve.add_option("--workers", o->workers, "Submissions played at once (the rest wait)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  serve
      .add_option("--wall-limit", o->limits.wall_s,
                  "Seconds a worker may take for all seeds of a submission; then it is killed "
                  "and the submission marked timeout")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 86400.0));
  serve.add_option("--cpu-limit", o->limits.cpu_s, "CPU seconds of a worker (RLIMIT_CPU)")
      ->capture_default_str()
      ->check(CLI::Range(1, 86400));
  auto memory_mib = std::make_shared<std::int64_t>(o->limits.address_space_bytes >> 20);
  serve.add_option("--memory-limit", *memory_mib, "MiB of address space of a worker (RLIMIT_AS)")
      ->capture_default_str()
      ->check(CLI::Range(64, 1 << 20));
  serve
      .add_option("--max-skill-bytes", o->max_skill_bytes,
                  "Largest skill file accepted (bytes); larger ones get 413")
      ->capture_default_str()
      ->check(CLI::Range(1, 16 << 20));
  serve
      .add_option("--max-per-minute", o->max_per_minute,
                  "Submissions a team may send per minute; more get 429")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  serve.add_option("--exercises", o->exercises,
                   "Where the exercises are (default: $LLSF_EXERCISES_DIR, else exercises/ of "
                   "the data directory)");
  serve.add_option("--viewer", o->viewer,
                   "The built viewer with leaderboard.html (default: $LLSF_VIEWER_DIR, else "
                   "viewer/dist of the data directory; `make viewer`)");
  serve.add_option("--worker", o->worker_program,
                   "The llsfsim program the workers run (default: this one)");
  serve.footer(
      "Teams open http://HOST:PORT/ (the leaderboard: a board per exercise and a submit form) or "
      "submit with `llsfsim exercise NN --skill FILE --submit http://HOST:PORT/ --team NAME`. "
      "Each submission is played by `llsfsim exercise NN --skill FILE --seeds SEEDS --json` in a "
      "sandboxed child process (own process group, rlimits, the wall-clock limit). For a room, "
      "give --host 0.0.0.0 or this machine's LAN address. Prints 'llsfsim hackathon: URL' and "
      "runs until Ctrl-C or SIGTERM; docs/hackathon-server.md.\n"
      "Exit code: 0 stopped, 2 bad options, cannot listen or cannot open --db, 3 internal error "
      "(a bug: please report it).");
  return [o, memory_mib, &serve](std::ostream& out, std::ostream& err) {
    if (!serve.parsed()) return kExitBadInput;
    o->limits.address_space_bytes = *memory_mib << 20;
    std::unique_ptr<HackathonServer> server;
    try {
      server = std::make_unique<HackathonServer>(*o);
    } catch (const core::UserError& e) {
      err << "llsfsim hackathon serve: " << e.what() << "\n";
      return kExitBadInput;
    }
    server->start();
    out << "llsfsim hackathon: " << server->url() << std::endl;
    wait_for_stop_signal();
    server->stop();
    return kExitOk;
  };
}

}  // namespace llsf::app
