// SPDX-License-Identifier: MIT
// The hackathon leaderboard (`llsfsim hackathon serve`, docs/hackathon-server.md): teams submit a
// skill file for an exercise over HTTP, sandboxed workers (sandbox.h) play it on hidden seeds with
// `llsfsim exercise NAME --skill FILE --seeds LIST --json`, and the board ranks the teams per
// exercise. Submissions live in the SQLite store (study::SubmissionStore).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "llsf/study/submission_store.h"
#include "sandbox.h"
#include "server.h"

namespace llsf::app {

/// What `llsfsim hackathon serve` is given.
struct HackathonOptions {
  std::string bind = "127.0.0.1";
  int port = 8080;
  std::string db = "llsfsim.db";    ///< a SQLite file (submissions and the statistics store)
  std::string exercises;            ///< "" = $LLSF_EXERCISES_DIR, else exercises/ of the data dir
  std::string viewer;               ///< the built viewer ("" = study::viewer_dir())
  std::string seeds = "1001-1005";  ///< the hidden seeds every submission is played on
  int workers = 2;                  ///< submissions played at once
  SandboxLimits limits;             ///< per worker
  std::int64_t max_skill_bytes = 256 * 1024;
  int max_per_minute = 6;      ///< submissions per team per minute
  int max_queued = 500;        ///< queued submissions at most (more: 503)
  std::string worker_program;  ///< the llsfsim the workers run ("" = /proc/self/exe)
  /// Log lines (no newline; from any thread). Empty: "llsfsim hackathon: <line>" on stderr.
  std::function<void(const std::string&)> log;
};

/// One exercise as the board shows it.
struct BoardExercise {
  std::string name;    ///< "01-drive-to-point"
  std::string title;   ///< "Drive to a point"
  std::string goal;    ///< "reach", "find", "points"
  std::string better;  ///< "lower" or "higher"
};

/// The exercises below `root` (directories with an exercise.yaml), by name.
std::vector<BoardExercise> board_exercises(const std::string& root);

/// What a finished worker's output means: parses the exercise command's --json object.
study::SubmissionOutcome outcome_of(const SandboxResult& r, const SandboxLimits& limits);

/// The leaderboard: HTTP routes on the viewer's server, the store and the worker threads.
class HackathonServer {
 public:
  /// Opens the store, reads the exercises, binds. Throws core::UserError (bad options, no
  /// exercises, cannot listen, the store cannot be opened).
  explicit HackathonServer(HackathonOptions options);
  ~HackathonServer();
  HackathonServer(const HackathonServer&) = delete;
  HackathonServer& operator=(const HackathonServer&) = delete;

  /// Re-queues what was running when the last server stopped, serves, starts the workers.
  void start();
  /// Stops serving and the workers; running workers are killed and their submissions stay
  /// "running" (re-queued by the next start()). Idempotent.
  void stop();
  /// "http://ADDR:PORT/".
  std::string url() const;
  int port() const;
  /// The store (for tests and the bench).
  study::SubmissionStore& store() { return *store_; }
  /// Answers one request (the server's routes; public for tests).
  std::optional<HttpAnswer> route(const HttpRequest& req);

 private:
  void work();
  void play(const study::Submission& s);
  void log(const std::string& line) const;
  const BoardExercise* find_exercise(const std::string& name, std::string& why) const;
  HttpAnswer submit(const HttpRequest& req);
  HttpAnswer board(const BoardExercise& ex);

  HackathonOptions options_;
  std::string root_;
  std::string program_;
  std::vector<BoardExercise> exercises_;
  int seed_count_ = 0;
  std::unique_ptr<study::SubmissionStore> store_;
  std::unique_ptr<Server> server_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stopping_{false};
  std::mutex submit_mutex_;  ///< rate check and insert as one step
};

}  // namespace llsf::app
