// SPDX-License-Identifier: MIT
// What the SQLite stores share (stats_store_sqlite.cpp, submission_store.cpp): handle deleters,
// exec(), an IMMEDIATE transaction and a prepared statement. Internal to study/.
#pragma once

#include <sqlite3.h>

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "llsf/study/stats_store.h"

namespace llsf::study::sqlite {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};

/// Runs `sql` (no results); a failure throws StatsError naming `path`.
inline void exec(sqlite3* db, const std::string& path, const char* sql) {
  char* msg = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &msg) != SQLITE_OK) {
    std::string text = msg ? msg : sqlite3_errmsg(db);
    sqlite3_free(msg);
    throw StatsError(path + ": " + text);
  }
}

/// BEGIN IMMEDIATE .. COMMIT; rolled back unless committed (also when an exception unwinds).
/// IMMEDIATE takes the write lock at once: writers of several processes take turns, whole
/// transactions at a time.
class Transaction {
 public:
  Transaction(sqlite3* db, const std::string& path) : db_(db), path_(path) {
    exec(db_, path_, "BEGIN IMMEDIATE");
  }
  ~Transaction() {
    if (!done_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    exec(db_, path_, "COMMIT");
    done_ = true;
  }

 private:
  sqlite3* db_;
  const std::string& path_;
  bool done_ = false;
};

// A prepared statement. start() resets it and clears its bindings; a Statement that returned
// rows is reset by the next start() or by finish().
class Statement {
 public:
  /// `context` (if given) comes after the path in error messages ("PATH: CONTEXT: step: ...").
  Statement(sqlite3* db, const std::string& path, std::string_view sql,
            std::string_view context = {})
      : db_(db), path_(&path), context_(context) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v3(db, sql.data(), static_cast<int>(sql.size()), SQLITE_PREPARE_PERSISTENT,
                           &s, nullptr) != SQLITE_OK) {
      fail("prepare");
    }
    stmt_.reset(s);
  }

  Statement& start() {
    sqlite3_reset(stmt_.get());
    sqlite3_clear_bindings(stmt_.get());
    next_ = 1;
    return *this;
  }
  Statement& bind(std::int64_t v) { return check(sqlite3_bind_int64(stmt_.get(), next_++, v)); }
  Statement& bind(int v) { return bind(static_cast<std::int64_t>(v)); }
  Statement& bind(double v) { return check(sqlite3_bind_double(stmt_.get(), next_++, v)); }
  Statement& bind(std::string_view v) {
    return check(sqlite3_bind_text(stmt_.get(), next_++, v.data(), static_cast<int>(v.size()),
                                   SQLITE_TRANSIENT));
  }
  Statement& bind(std::optional<double> v) { return v ? bind(*v) : bind_null(); }
  Statement& bind_null() { return check(sqlite3_bind_null(stmt_.get(), next_++)); }

  // One step: true if a row is ready, false when done.
  bool step() {
    const int rc = sqlite3_step(stmt_.get());
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail("step");
  }
  // Runs a statement that returns no rows.
  void run() {
    while (step()) {
    }
    finish();
  }
  void finish() { sqlite3_reset(stmt_.get()); }

  std::int64_t int64(int col) const { return sqlite3_column_int64(stmt_.get(), col); }
  double real(int col) const { return sqlite3_column_double(stmt_.get(), col); }
  std::optional<double> real_or_null(int col) const {
    if (null(col)) return std::nullopt;
    return real(col);
  }
  bool null(int col) const { return sqlite3_column_type(stmt_.get(), col) == SQLITE_NULL; }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_.get(), col);
    return p ? std::string(reinterpret_cast<const char*>(p),
                           static_cast<std::size_t>(sqlite3_column_bytes(stmt_.get(), col)))
             : std::string();
  }

 private:
  Statement& check(int rc) {
    if (rc != SQLITE_OK) fail("bind");
    return *this;
  }
  [[noreturn]] void fail(const char* what) const {
    // Reset so that a failed statement does not keep the database locked.
    if (stmt_) sqlite3_reset(stmt_.get());
    std::string message = *path_ + ": ";
    if (!context_.empty()) message.append(context_).append(": ");
    throw StatsError(message + what + ": " + sqlite3_errmsg(db_));
  }

  sqlite3* db_;
  const std::string* path_;
  std::string context_;
  std::unique_ptr<sqlite3_stmt, StmtFinalizer> stmt_;
  int next_ = 1;
};

}  // namespace llsf::study::sqlite
