// SPDX-License-Identifier: MIT
// The hackathon leaderboard's submissions in the statistics store's SQLite file: its own table,
// its own migrations (hackathon_schema_migrations, the style of stats_store_sqlite.cpp), and the
// ranking. The statistics store is opened (and migrated) first, so that the file stays one the
// statistics store accepts.
#include "llsf/study/submission_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <map>
#include <memory>
#include <stdexcept>

#include "llsf/study/stats_store.h"
#include "sqlite_util.h"

namespace llsf::study {

namespace {

// The migrations: kSql[v - 1] takes the hackathon tables from version v - 1 to v.
constexpr std::array<const char*, SubmissionStore::kSchemaVersion> kSql = {
    R"sql(
CREATE TABLE hackathon_submissions (
  id          INTEGER PRIMARY KEY,
  team        TEXT    NOT NULL,
  exercise    TEXT    NOT NULL,
  file_name   TEXT    NOT NULL,
  content     TEXT    NOT NULL,
  sha256      TEXT    NOT NULL,
  received    TEXT    NOT NULL,
  received_ms INTEGER NOT NULL,
  status      TEXT    NOT NULL
              CHECK (status IN ('queued', 'running', 'done', 'failed', 'timeout')),
  seeds       TEXT    NOT NULL,
  started     TEXT,
  finished    TEXT,
  passed      INTEGER,
  total       INTEGER,
  value       REAL,
  verdict     TEXT,
  better      TEXT,
  result      TEXT,
  error       TEXT
);
CREATE INDEX hackathon_submissions_by_exercise ON hackathon_submissions (exercise, status);
CREATE INDEX hackathon_submissions_by_team ON hackathon_submissions (team, received_ms);
)sql",
};
constexpr std::array<const char*, SubmissionStore::kSchemaVersion> kDescriptions = {
    "hackathon_submissions"};

const std::array<const char*, 5> kStatusNames = {"queued", "running", "done", "failed", "timeout"};

SubmissionStatus status_of(const std::string& s) {
  for (std::size_t i = 0; i < kStatusNames.size(); ++i) {
    if (s == kStatusNames[i]) return static_cast<SubmissionStatus>(i);
  }
  throw StatsError("unknown submission status '" + s + "'");
}

std::string iso_of_ms(std::int64_t ms) {
  const std::time_t secs = static_cast<std::time_t>(ms / 1000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  std::array<char, 96> buf{};
  std::snprintf(buf.data(), buf.size(), "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>(ms % 1000));
  return buf.data();
}

/// Now as ISO 8601 UTC with milliseconds.
std::string iso_now() {
  return iso_of_ms(std::chrono::duration_cast<std::chrono::milliseconds>(
                       std::chrono::system_clock::now().time_since_epoch())
                       .count());
}

using sqlite::DbCloser;

using sqlite::Statement;

// A statement prepared for one call (the store's calls are few and small); errors name the table.
Statement stmt(sqlite3* db, const std::string& path, const char* sql) {
  return Statement(db, path, sql, "hackathon submissions");
}

using sqlite::exec;
using sqlite::Transaction;

// The columns every query reads, in this order (read_row()).
constexpr const char* kColumns =
    "id, team, exercise, file_name, sha256, received, received_ms, status, seeds, started, "
    "finished, passed, total, value, verdict, better, result, error";

Submission read_row(const Statement& q) {
  Submission s;
  s.id = q.int64(0);
  s.team = q.text(1);
  s.exercise = q.text(2);
  s.file_name = q.text(3);
  s.sha256 = q.text(4);
  s.received = q.text(5);
  s.received_ms = q.int64(6);
  s.status = status_of(q.text(7));
  s.seeds = q.text(8);
  s.started = q.text(9);
  s.finished = q.text(10);
  s.passed = static_cast<int>(q.int64(11));
  s.total = static_cast<int>(q.int64(12));
  s.value = q.real_or_null(13);
  s.verdict = q.text(14);
  s.better = q.text(15);
  s.result = q.text(16);
  s.error = q.text(17);
  return s;
}

// ---- SHA-256 (FIPS 180-4, section 6.2) ---------------------------------------------------------

constexpr std::array<std::uint32_t, 64> kK = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

constexpr std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

}  // namespace

std::string sha256_hex(std::string_view data) {
  std::array<std::uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                                    0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  // The message, padded: 0x80, zeros, the length in bits as 64-bit big endian.
  std::string m(data);
  const std::uint64_t bits = static_cast<std::uint64_t>(data.size()) * 8;
  m += static_cast<char>(0x80);
  while (m.size() % 64 != 56) m += '\0';
  for (int i = 7; i >= 0; --i) m += static_cast<char>((bits >> (i * 8)) & 0xff);
  std::array<std::uint32_t, 64> w{};
  for (std::size_t block = 0; block < m.size(); block += 64) {
    for (std::size_t t = 0; t < 16; ++t) {
      w[t] = 0;
      for (std::size_t b = 0; b < 4; ++b) {
        w[t] = (w[t] << 8) | static_cast<unsigned char>(m[block + t * 4 + b]);
      }
    }
    for (std::size_t t = 16; t < 64; ++t) {
      const std::uint32_t s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
      const std::uint32_t s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
      w[t] = w[t - 16] + s0 + w[t - 7] + s1;
    }
    std::array<std::uint32_t, 8> v = h;
    for (std::size_t t = 0; t < 64; ++t) {
      const std::uint32_t e = v[4];
      const std::uint32_t a = v[0];
      const std::uint32_t t1 = v[7] + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) +
                               ((e & v[5]) ^ (~e & v[6])) + kK[t] + w[t];
      const std::uint32_t t2 =
          (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & v[1]) ^ (a & v[2]) ^ (v[1] & v[2]));
      v = {t1 + t2, v[0], v[1], v[2], v[3] + t1, v[4], v[5], v[6]};
    }
    for (std::size_t i = 0; i < 8; ++i) h[i] += v[i];
  }
  std::string hex;
  hex.reserve(64);
  for (const std::uint32_t x : h) {
    std::array<char, 9> buf{};
    std::snprintf(buf.data(), buf.size(), "%08x", x);
    hex += buf.data();
  }
  return hex;
}

bool is_valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    int n = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      ++i;
      continue;
    }
    if ((c & 0xe0) == 0xc0) {
      n = 1, cp = c & 0x1f;
    } else if ((c & 0xf0) == 0xe0) {
      n = 2, cp = c & 0x0f;
    } else if ((c & 0xf8) == 0xf0) {
      n = 3, cp = c & 0x07;
    } else {
      return false;
    }
    if (i + static_cast<std::size_t>(n) >= s.size()) return false;
    for (int k = 1; k <= n; ++k) {
      const auto d = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((d & 0xc0) != 0x80) return false;
      cp = (cp << 6) | (d & 0x3f);
    }
    static constexpr std::array<std::uint32_t, 4> kMin = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[static_cast<std::size_t>(n)] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) {
      return false;
    }
    i += static_cast<std::size_t>(n) + 1;
  }
  return true;
}

std::string_view to_string(SubmissionStatus s) {
  return kStatusNames.at(static_cast<std::size_t>(s));
}

// ---- The store ---------------------------------------------------------------------------------

struct SubmissionStore::Impl {
  std::string path;
  std::unique_ptr<sqlite3, DbCloser> db;
};

SubmissionStore::SubmissionStore(const std::string& path) : impl_(std::make_unique<Impl>()) {
  if (is_database_url(path)) {
    throw StatsError(masked_database_url(path) +
                     ": the leaderboard keeps its submissions in a SQLite file; give --db FILE");
  }
  // The statistics store's tables first: a file the statistics store opens afterwards must not
  // look like "not an llsfsim statistics store (it has other tables)".
  { const StatsStore stats(path); }
  impl_->path = path;
  sqlite3* raw = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  impl_->db.reset(raw);
  if (rc != SQLITE_OK) {
    throw StatsError(path +
                     ": cannot open the store: " + (raw ? sqlite3_errmsg(raw) : "out of memory"));
  }
  sqlite3* db = impl_->db.get();
  sqlite3_busy_timeout(db, 10000);
  Transaction t(db, impl_->path);
  exec(db, impl_->path,
       "CREATE TABLE IF NOT EXISTS hackathon_schema_migrations (version INTEGER PRIMARY KEY, "
       "description TEXT NOT NULL, applied TEXT)");
  int version = 0;
  {
    Statement q =
        stmt(db, impl_->path, "SELECT coalesce(max(version), 0) FROM hackathon_schema_migrations");
    if (q.step()) version = static_cast<int>(q.int64(0));
  }
  if (version > kSchemaVersion) {
    throw StatsError(path + ": hackathon tables of version " + std::to_string(version) +
                     " (this llsfsim reads versions up to " + std::to_string(kSchemaVersion) +
                     "; a newer llsfsim wrote them)");
  }
  for (int v = version + 1; v <= kSchemaVersion; ++v) {
    exec(db, impl_->path, kSql.at(static_cast<std::size_t>(v - 1)));
    stmt(db, impl_->path,
         "INSERT INTO hackathon_schema_migrations (version, description, applied) VALUES (?, ?, "
         "strftime('%Y-%m-%dT%H:%M:%SZ', 'now'))")
        .bind(v)
        .bind(std::string_view(kDescriptions.at(static_cast<std::size_t>(v - 1))))
        .run();
  }
  t.commit();
}

SubmissionStore::~SubmissionStore() = default;

std::int64_t SubmissionStore::add(const std::string& team, const std::string& exercise,
                                  const std::string& file_name, const std::string& content,
                                  const std::string& seeds, std::int64_t received_ms) {
  const std::lock_guard lock(mutex_);
  sqlite3* db = impl_->db.get();
  stmt(db, impl_->path,
       "INSERT INTO hackathon_submissions (team, exercise, file_name, content, sha256, received, "
       "received_ms, status, seeds) VALUES (?, ?, ?, ?, ?, ?, ?, 'queued', ?)")
      .bind(std::string_view(team))
      .bind(std::string_view(exercise))
      .bind(std::string_view(file_name))
      .bind(std::string_view(content))
      .bind(std::string_view(sha256_hex(content)))
      .bind(std::string_view(iso_of_ms(received_ms)))
      .bind(received_ms)
      .bind(std::string_view(seeds))
      .run();
  return sqlite3_last_insert_rowid(db);
}

int SubmissionStore::count_since(const std::string& team, std::int64_t since_ms) {
  const std::lock_guard lock(mutex_);
  Statement q =
      stmt(impl_->db.get(), impl_->path,
           "SELECT count(*) FROM hackathon_submissions WHERE team = ? AND received_ms >= ?");
  q.bind(std::string_view(team)).bind(since_ms);
  return q.step() ? static_cast<int>(q.int64(0)) : 0;
}

std::optional<Submission> SubmissionStore::claim_next() {
  const std::lock_guard lock(mutex_);
  sqlite3* db = impl_->db.get();
  Transaction t(db, impl_->path);
  std::optional<Submission> s;
  {
    Statement q =
        stmt(db, impl_->path,
             (std::string("SELECT ") + kColumns +
              ", content FROM hackathon_submissions WHERE status = 'queued' ORDER BY id LIMIT 1")
                 .c_str());
    if (!q.step()) return std::nullopt;
    s = read_row(q);
    s->content = q.text(18);
  }
  s->status = SubmissionStatus::kRunning;
  s->started = iso_now();
  stmt(db, impl_->path,
       "UPDATE hackathon_submissions SET status = 'running', started = ? WHERE id = ?")
      .bind(std::string_view(s->started))
      .bind(s->id)
      .run();
  t.commit();
  return s;
}

void SubmissionStore::finish(std::int64_t id, const SubmissionOutcome& o) {
  const std::lock_guard lock(mutex_);
  stmt(impl_->db.get(), impl_->path,
       "UPDATE hackathon_submissions SET status = ?, finished = ?, passed = ?, total = ?, value = "
       "?, verdict = ?, better = ?, result = ?, error = ? WHERE id = ?")
      .bind(to_string(o.status))
      .bind(std::string_view(iso_now()))
      .bind(o.passed)
      .bind(o.total)
      .bind(o.value)
      .bind(std::string_view(o.verdict))
      .bind(std::string_view(o.better))
      .bind(std::string_view(o.result))
      .bind(std::string_view(o.error))
      .bind(id)
      .run();
}

int SubmissionStore::requeue_running() {
  const std::lock_guard lock(mutex_);
  stmt(impl_->db.get(), impl_->path,
       "UPDATE hackathon_submissions SET status = 'queued', started = NULL WHERE status = "
       "'running'")
      .run();
  return sqlite3_changes(impl_->db.get());
}

std::optional<Submission> SubmissionStore::get(std::int64_t id) {
  const std::lock_guard lock(mutex_);
  Statement q =
      stmt(impl_->db.get(), impl_->path,
           (std::string("SELECT ") + kColumns + ", content FROM hackathon_submissions WHERE id = ?")
               .c_str());
  q.bind(id);
  if (!q.step()) return std::nullopt;
  Submission s = read_row(q);
  s.content = q.text(18);
  return s;
}

std::vector<Submission> SubmissionStore::list(const std::string& exercise, int limit) {
  const std::lock_guard lock(mutex_);
  Statement q =
      stmt(impl_->db.get(), impl_->path,
           (std::string("SELECT ") + kColumns +
            " FROM hackathon_submissions WHERE ? = '' OR exercise = ? ORDER BY id DESC LIMIT ?")
               .c_str());
  q.bind(std::string_view(exercise)).bind(std::string_view(exercise)).bind(limit);
  std::vector<Submission> out;
  while (q.step()) out.push_back(read_row(q));
  return out;
}

std::vector<Submission> SubmissionStore::done(const std::string& exercise) {
  const std::lock_guard lock(mutex_);
  Statement q =
      stmt(impl_->db.get(), impl_->path,
           (std::string("SELECT ") + kColumns +
            " FROM hackathon_submissions WHERE exercise = ? AND status = 'done' ORDER BY id")
               .c_str());
  q.bind(std::string_view(exercise));
  std::vector<Submission> out;
  while (q.step()) out.push_back(read_row(q));
  return out;
}

std::vector<std::pair<std::string, int>> SubmissionStore::counts() {
  const std::lock_guard lock(mutex_);
  Statement q =
      stmt(impl_->db.get(), impl_->path,
           "SELECT status, count(*) FROM hackathon_submissions GROUP BY status ORDER BY status");
  std::vector<std::pair<std::string, int>> out;
  while (q.step()) out.emplace_back(q.text(0), static_cast<int>(q.int64(1)));
  return out;
}

// ---- Ranking -----------------------------------------------------------------------------------

namespace {

/// Whether `a` ranks before `b` (both done submissions of one exercise).
bool ranks_before(const Submission& a, const Submission& b) {
  if (a.passed != b.passed) return a.passed > b.passed;
  if (a.value.has_value() != b.value.has_value()) return a.value.has_value();
  if (a.value && *a.value != *b.value) {
    return a.better == "higher" ? *a.value > *b.value : *a.value < *b.value;
  }
  if (a.received_ms != b.received_ms) return a.received_ms < b.received_ms;
  return a.id < b.id;
}

}  // namespace

std::vector<BoardEntry> rank_board(const std::vector<Submission>& done) {
  std::map<std::string, BoardEntry> best;
  for (const Submission& s : done) {
    if (s.status != SubmissionStatus::kDone) continue;
    auto [it, fresh] = best.try_emplace(s.team, BoardEntry{0, s, 0});
    ++it->second.submissions;
    if (!fresh && ranks_before(s, it->second.best)) it->second.best = s;
  }
  std::vector<BoardEntry> board;
  board.reserve(best.size());
  for (auto& [team, e] : best) board.push_back(std::move(e));
  std::sort(board.begin(), board.end(),
            [](const BoardEntry& a, const BoardEntry& b) { return ranks_before(a.best, b.best); });
  for (std::size_t i = 0; i < board.size(); ++i) board[i].rank = static_cast<int>(i) + 1;
  return board;
}

}  // namespace llsf::study
