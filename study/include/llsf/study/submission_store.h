// SPDX-License-Identifier: MIT
// SubmissionStore: the hackathon leaderboard's submissions (`llsfsim hackathon serve`) in the
// statistics store's SQLite file, in tables of their own (`hackathon_submissions`, versioned by
// `hackathon_schema_migrations`; docs/hackathon-server.md). Thread-safe: one connection behind a
// mutex, every call one short transaction.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace llsf::study {

/// The SHA-256 digest of `data` as 64 lower-case hex digits (FIPS 180-4).
std::string sha256_hex(std::string_view data);

/// Whether `s` is well-formed UTF-8 (no overlong forms, no surrogates, at most U+10FFFF).
bool is_valid_utf8(std::string_view s);

/// A submission's state: queued -> running -> done | failed | timeout.
enum class SubmissionStatus : std::uint8_t { kQueued, kRunning, kDone, kFailed, kTimeout };

/// "queued", "running", "done", "failed", "timeout".
std::string_view to_string(SubmissionStatus s);

/// One row of `hackathon_submissions`.
struct Submission {
  std::int64_t id = 0;
  std::string team;
  std::string exercise;   ///< the exercise's directory name ("01-drive-to-point")
  std::string file_name;  ///< as the team named it (metadata)
  std::string content;    ///< the skill file
  std::string sha256;     ///< of content
  std::string received;   ///< UTC, ISO 8601 with milliseconds (wall clock; never in a result)
  std::int64_t received_ms = 0;  ///< the same, ms since the epoch (ordering, rate limits)
  SubmissionStatus status = SubmissionStatus::kQueued;
  std::string seeds;  ///< the hidden seeds played ("1001-1005"; never shown to teams)
  std::string started;
  std::string finished;
  int passed = 0;               ///< seeds passed (done only)
  int total = 0;                ///< seeds played (done only)
  std::optional<double> value;  ///< the runs' mean value (distance or points); none: nothing
  std::string verdict;          ///< PASS, FAIL, NOT RUN (done only)
  std::string better;           ///< "lower" or "higher" (done only)
  std::string result;           ///< the worker's JSON (done only)
  std::string error;            ///< why failed/timeout, or the worker's standard error's tail
};

/// What a finished worker left.
struct SubmissionOutcome {
  SubmissionStatus status = SubmissionStatus::kDone;  ///< kDone, kFailed or kTimeout
  int passed = 0;
  int total = 0;
  std::optional<double> value;
  std::string verdict;
  std::string better;
  std::string result;
  std::string error;
};

/// The submissions table in a SQLite file shared with the statistics store.
class SubmissionStore {
 public:
  /// Opens (creating if missing) `path` and migrates the statistics store's tables and then the
  /// hackathon's. Throws StatsError naming the file (a postgresql:// URL is refused: the
  /// leaderboard keeps SQLite only).
  explicit SubmissionStore(const std::string& path);
  ~SubmissionStore();
  SubmissionStore(const SubmissionStore&) = delete;
  SubmissionStore& operator=(const SubmissionStore&) = delete;

  /// The schema version of the hackathon tables this code creates.
  static constexpr int kSchemaVersion = 1;

  /// Stores a new queued submission (received now); returns its id.
  std::int64_t add(const std::string& team, const std::string& exercise,
                   const std::string& file_name, const std::string& content,
                   const std::string& seeds, std::int64_t received_ms);
  /// Submissions of `team` received at or after `since_ms`.
  int count_since(const std::string& team, std::int64_t since_ms);
  /// Marks the oldest queued submission running and returns it; nullopt when none is queued.
  std::optional<Submission> claim_next();
  /// Stores a worker's outcome.
  void finish(std::int64_t id, const SubmissionOutcome& outcome);
  /// Puts every running submission back in the queue (after a crash); returns how many.
  int requeue_running();
  /// One submission.
  std::optional<Submission> get(std::int64_t id);
  /// Submissions of one exercise ("" = all), newest first, without their content, at most
  /// `limit`.
  std::vector<Submission> list(const std::string& exercise, int limit);
  /// The done submissions of one exercise, without their content, oldest first.
  std::vector<Submission> done(const std::string& exercise);
  /// Submissions per status ("queued", ...) over all exercises.
  std::vector<std::pair<std::string, int>> counts();

 private:
  struct Impl;
  std::mutex mutex_;
  std::unique_ptr<Impl> impl_;
};

/// One row of a leaderboard: a team's best submission of an exercise.
struct BoardEntry {
  int rank = 0;  ///< 1, 2, ... (ties share no rank: earlier submission first)
  Submission best;
  int submissions = 0;  ///< the team's done submissions of the exercise
};

/// Ranks the done submissions of one exercise: a team's best submission counts; more seeds
/// passed first, then the better value ("lower" or "higher"; none last), then earlier received.
std::vector<BoardEntry> rank_board(const std::vector<Submission>& done);

}  // namespace llsf::study
