// SPDX-License-Identifier: MIT
// What the SQLite stores share (stats_store_sqlite.cpp, submission_store.cpp): handle deleters,
// exec() and an IMMEDIATE transaction. Internal to study/.
#pragma once

#include <sqlite3.h>

#include <string>

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

}  // namespace llsf::study::sqlite
