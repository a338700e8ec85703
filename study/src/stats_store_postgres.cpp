// SPDX-License-Identifier: MIT
// The statistics store in a PostgreSQL database (libpqxx; docs/statistics.md, "PostgreSQL").
// Many processes write one store at once: each run in one READ COMMITTED transaction, its
// identity (batch, variant, seed) guarded by the unique constraint with ON CONFLICT, and every
// operation retried after a serialization failure, a deadlock or a lost connection (writes are
// idempotent, so a retry after a commit whose answer was lost finds the run and writes nothing).
#include <libpq-fe.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <pqxx/pqxx>
#include <string>
#include <thread>

#include "stats_backend.h"

namespace llsf::study {

namespace {

// The current UTC time as the schema's text (kPostgresDialect.now).
constexpr const char* kCreated = kPostgresDialect.now;

// The migrations in PostgreSQL's dialect (schema_sql, stats_store.cpp).
const std::array<std::string, kSchemaVersion>& postgres_migrations() {
  static const std::array<std::string, kSchemaVersion> sql = schema_sql(kPostgresDialect);
  return sql;
}

// The advisory lock that serialises migrations of one database ("llsf" in ASCII).
constexpr std::int64_t kMigrationLock = 0x6c6c7366;

// A literal of a double that reads back bit for bit (inf and NaN as PostgreSQL spells them).
std::string real_literal(double v) {
  if (std::isnan(v)) return "'NaN'";
  if (std::isinf(v)) return v > 0 ? "'Infinity'" : "'-Infinity'";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Thrown inside a transaction to start it again (a concurrent writer changed what it read).
struct RetryTransaction {};

// How long a lost connection is retried before an operation fails: LLSF_DB_RETRY_S, else 60 s.
std::chrono::milliseconds retry_window() {
  if (const char* s = std::getenv("LLSF_DB_RETRY_S")) {
    char* end = nullptr;
    const double v = std::strtod(s, &end);
    if (end != s && *end == '\0' && v >= 0.0 && v <= 86400.0) {
      return std::chrono::milliseconds(static_cast<std::int64_t>(v * 1000.0));
    }
  }
  return std::chrono::seconds(60);
}

// The connection's parameters from the URL, as a libpq key=value string: connect_timeout 10 s
// and application_name llsfsim unless the URL or the environment sets them. What the URL leaves
// out, libpq takes from the PG* environment variables.
struct ConnInfo {
  std::string conninfo;
  std::string password;  ///< from the URL or PGPASSWORD: masked in every message
};

ConnInfo parse_url(const std::string& url, const std::string& shown) {
  char* error = nullptr;
  PQconninfoOption* options = PQconninfoParse(url.c_str(), &error);
  if (options == nullptr) {
    std::string why = error != nullptr ? error : "out of memory";
    PQfreemem(error);
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
    throw StatsError(shown +
                     ": not a valid PostgreSQL URL (postgresql://USER@HOST:PORT/DB): " + why);
  }
  ConnInfo info;
  bool timeout = std::getenv("PGCONNECT_TIMEOUT") != nullptr;
  bool app = std::getenv("PGAPPNAME") != nullptr;
  auto quoted = [](const char* v) {
    std::string out = "'";
    for (const char* p = v; *p != '\0'; ++p) {
      if (*p == '\'' || *p == '\\') out += '\\';
      out += *p;
    }
    return out + "'";
  };
  for (const PQconninfoOption* o = options; o->keyword != nullptr; ++o) {
    if (o->val == nullptr) continue;
    const std::string key = o->keyword;
    if (key == "password") info.password = o->val;
    if (key == "connect_timeout") timeout = true;
    if (key == "application_name") app = true;
    info.conninfo += key + "=" + quoted(o->val) + " ";
  }
  PQconninfoFree(options);
  if (!timeout) info.conninfo += "connect_timeout=10 ";
  if (!app) info.conninfo += "application_name=llsfsim ";
  if (info.password.empty()) {
    if (const char* p = std::getenv("PGPASSWORD")) info.password = p;
  }
  return info;
}

// ---- The backend -----------------------------------------------------------------------------

class PostgresBackend final : public StatsBackend {
 public:
  explicit PostgresBackend(const std::string& url)
      : path_(masked_database_url(url)), info_(parse_url(url, path_)), window_(retry_window()) {
    // The first connection is not retried: a wrong URL or a server that is not there is an
    // error at once (`llsfsim batch` exits 2 before any game).
    try {
      connect();
    } catch (const pqxx::failure& e) {
      throw StatsError(path_ + ": cannot connect to the PostgreSQL server: " + clean(e.what()));
    }
    with_retry("creating the schema", [&](pqxx::connection& c) { migrate(c); });
  }

  const std::string& path() const override { return path_; }

  void require_writable() const override {
    const std::string problem = with_retry("checking write access", [&](pqxx::connection& c) {
      pqxx::work w(c);
      const pqxx::row r = w.exec1(
          "SELECT pg_is_in_recovery(), current_setting('transaction_read_only') = 'on', "
          "has_table_privilege('batches', 'SELECT, INSERT, UPDATE') AND "
          "has_table_privilege('runs', 'SELECT, INSERT, DELETE') AND "
          "has_table_privilege('statistics', 'SELECT, INSERT, DELETE') AND "
          "has_table_privilege('orders', 'SELECT, INSERT, DELETE') AND "
          "has_table_privilege('tests', 'SELECT, INSERT, DELETE') AND "
          "has_table_privilege('awards', 'SELECT, INSERT, DELETE') AND "
          "has_table_privilege('events', 'SELECT, INSERT, DELETE') AND "
          "has_sequence_privilege(pg_get_serial_sequence('batches', 'id'), 'USAGE') AND "
          "has_sequence_privilege(pg_get_serial_sequence('runs', 'id'), 'USAGE'), current_user");
      if (r[0].as<bool>()) return std::string("the server is a read-only standby");
      if (r[1].as<bool>()) return std::string("the session is read-only");
      if (!r[2].as<bool>()) {
        return "the role " + r[3].as<std::string>() + " may not write the store's tables";
      }
      return std::string();
    });
    if (!problem.empty()) {
      throw StatsError(path_ + ": the statistics store is read-only: " + problem +
                       ": no run can be written to it");
    }
  }

  std::int64_t open_batch(const BatchKey& key) override {
    const std::string kind = key.kind == BatchKey::Kind::kBatch ? "batch" : "run";
    return with_retry("opening the batch", [&](pqxx::connection& c) {
      pqxx::work w(c);
      const pqxx::result found =
          w.exec_prepared("find_batch", kind, key.scenario_hash, key.runs_per_variant);
      if (!found.empty()) return found[0][0].as<std::int64_t>();
      // Two writers may create the same batch at once: one inserts, the other finds it.
      const pqxx::result made =
          w.exec_prepared("insert_batch", kind, key.scenario_file, key.scenario_name,
                          key.scenario_hash, key.runs_per_variant, std::max(1, key.variants),
                          join_seeds(key.seeds), std::string(llsfsim_version()));
      if (!made.empty()) {
        const auto id = made[0][0].as<std::int64_t>();
        w.commit();
        return id;
      }
      const pqxx::result again =
          w.exec_prepared("find_batch", kind, key.scenario_hash, key.runs_per_variant);
      if (again.empty()) throw RetryTransaction{};  // deleted meanwhile: start over
      return again[0][0].as<std::int64_t>();
    });
  }

  void finish_batch(std::int64_t batch_id) override {
    with_retry("finishing the batch", [&](pqxx::connection& c) {
      pqxx::work w(c);
      w.exec_prepared("finish_batch", batch_id);
      w.commit();
    });
  }

  void remove_empty_batch(std::int64_t batch_id) override {
    with_retry("removing an empty batch", [&](pqxx::connection& c) {
      pqxx::work w(c);
      w.exec_prepared("remove_empty_batch", batch_id);
      w.commit();
    });
  }

  std::optional<StoredBatch> batch(std::int64_t batch_id) const override {
    const std::vector<StoredBatch> b = read_batches(" WHERE id = " + std::to_string(batch_id));
    if (b.empty()) return std::nullopt;
    return b.front();
  }

  std::vector<StoredBatch> batches() const override { return read_batches(" ORDER BY id"); }

  std::int64_t add_run(std::int64_t batch_id, const RunResult& r, bool replace) override {
    const RunRows rows = make_run_rows(r);
    const std::string recording =
        r.recording.empty() ? std::string() : stored_recording_path(path_, r.recording);
    return with_retry("storing the run", [&](pqxx::connection& c) {
      pqxx::work w(c);
      if (replace) w.exec_prepared("delete_run", batch_id, r.variant, rows.seed);
      const pqxx::result inserted = w.exec_prepared(
          "insert_run", batch_id, r.scenario, r.variant, rows.seed, std::string(llsfsim_version()),
          rows.result_hash, r.passed() ? 1 : 0, r.points, real_literal_text(r.game_time_s),
          real_literal_text(r.cpu_s), real_literal_text(r.real_time_factor), recording);
      if (inserted.empty()) {
        // The key is taken (ON CONFLICT DO NOTHING waited for the writer that took it).
        if (replace) throw RetryTransaction{};  // stored after our delete: delete it again
        const pqxx::result old = w.exec_prepared("find_run", batch_id, r.variant, rows.seed);
        if (old.empty()) throw RetryTransaction{};  // replaced or deleted meanwhile
        const std::string hash = old[0][1].as<std::string>();
        if (hash != rows.result_hash) {
          throw StatsError(conflicting_run_message(path_, batch_id, r, hash));
        }
        return old[0][0].as<std::int64_t>();  // the same run: nothing written (rolled back)
      }
      const auto run_id = inserted[0][0].as<std::int64_t>();
      const std::string id = std::to_string(run_id);

      // The run's children: one multi-row INSERT per table (few round trips per run).
      auto insert_rows = [&](const char* head, std::size_t n, auto&& row) {
        if (n == 0) return;
        std::string sql = head;
        for (std::size_t i = 0; i < n; ++i) {
          sql += i == 0 ? " (" : ", (";
          sql += row(i);
          sql += ')';
        }
        w.exec(sql);
      };
      auto q = [&](const std::string& s) { return w.quote(s); };
      auto num = [](auto v) { return std::to_string(v); };
      auto or_null = [&](const std::string& s) { return s.empty() ? std::string("NULL") : q(s); };
      auto int_or_null = [](int v) { return v < 0 ? std::string("NULL") : std::to_string(v); };
      insert_rows("INSERT INTO statistics (run_id, name, value) VALUES", rows.statistics.size(),
                  [&](std::size_t i) {
                    return id + ", " + q(rows.statistics[i].first) + ", " +
                           real_literal(rows.statistics[i].second);
                  });
      insert_rows(
          "INSERT INTO orders (run_id, order_id, product, requested, delivered, window_begin_s, "
          "window_end_s) VALUES",
          r.orders.size(), [&](std::size_t i) {
            const OrderResult& o = r.orders[i];
            return id + ", " + num(o.id) + ", " + q(o.product) + ", " + num(o.requested) + ", " +
                   num(o.delivered) + ", " + num(o.window_begin_s) + ", " + num(o.window_end_s);
          });
      insert_rows("INSERT INTO tests (run_id, idx, name, passed, detail, at_s) VALUES",
                  r.tests.size(), [&](std::size_t i) {
                    const TestVerdict& v = r.tests[i];
                    return id + ", " + num(i) + ", " + q(v.name) + ", " + (v.passed ? "1" : "0") +
                           ", " + q(v.detail) + ", " + real_literal(v.at_s);
                  });
      insert_rows(
          "INSERT INTO awards (run_id, idx, time_s, game_time_s, phase, points, reason, device, "
          "order_id, puck) VALUES",
          r.awards.size(), [&](std::size_t i) {
            const RunAward& a = r.awards[i];
            return id + ", " + num(i) + ", " + real_literal(a.time_s) + ", " +
                   real_literal(a.game_time_s) + ", " + q(a.phase) + ", " + num(a.points) + ", " +
                   q(a.reason) + ", " + or_null(a.device) + ", " + int_or_null(a.order) + ", " +
                   int_or_null(a.puck);
          });
      insert_rows("INSERT INTO events (run_id, idx, time_s, kind, name, value, detail) VALUES",
                  rows.events.size(), [&](std::size_t i) {
                    const RunEvent& e = rows.events[i];
                    return id + ", " + num(i) + ", " + real_literal(e.time_s) + ", " + q(e.kind) +
                           ", " + q(e.name) + ", " + real_literal(e.value) + ", " + q(e.detail);
                  });
      w.commit();
      return run_id;
    });
  }

  std::vector<StoredRun> runs(std::int64_t batch_id) const override {
    return read_runs("WHERE batch_id = " + std::to_string(batch_id) + " ORDER BY id");
  }

  std::optional<StoredRun> run(std::int64_t run_id) const override {
    std::vector<StoredRun> r = read_runs("WHERE id = " + std::to_string(run_id));
    if (r.empty()) return std::nullopt;
    return std::move(r.front());
  }

  std::vector<std::pair<std::string, double>> statistics(std::int64_t run_id) const override {
    return with_retry("reading statistics", [&](pqxx::connection& c) {
      pqxx::work w(c);
      std::vector<std::pair<std::string, double>> out;
      for (const pqxx::row& row : w.exec_prepared("select_stats", run_id)) {
        out.emplace_back(row[0].as<std::string>(), row[1].as<double>());
      }
      return out;
    });
  }

  std::vector<RunAward> awards(std::int64_t run_id) const override {
    return with_retry("reading awards", [&](pqxx::connection& c) {
      pqxx::work w(c);
      std::vector<RunAward> out;
      for (const pqxx::row& row : w.exec_prepared("select_awards", run_id)) {
        RunAward& a = out.emplace_back();
        a.time_s = row[0].as<double>();
        a.game_time_s = row[1].as<double>();
        a.phase = row[2].as<std::string>();
        a.points = row[3].as<int>();
        a.reason = row[4].as<std::string>();
        a.device = row[5].as<std::string>();
        a.order = row[6].as<int>();
        a.puck = row[7].as<int>();
      }
      return out;
    });
  }

  std::int64_t count_rows(std::string_view table) const override {
    return with_retry("counting rows", [&](pqxx::connection& c) {
      pqxx::work w(c);
      return w.exec1("SELECT count(*) FROM " + std::string(table))[0].as<std::int64_t>();
    });
  }

 private:
  // A double as the text of a parameter (exact, like real_literal without quotes).
  static std::string real_literal_text(double v) {
    std::string s = real_literal(v);
    if (s.front() == '\'') s = s.substr(1, s.size() - 2);
    return s;
  }

  // `what` without the password (libpq's messages do not show it; kept out regardless), one line.
  std::string clean(std::string what) const {
    if (!info_.password.empty()) {
      for (std::size_t p = what.find(info_.password); p != std::string::npos;
           p = what.find(info_.password, p + 3)) {
        what.replace(p, info_.password.size(), "***");
      }
    }
    // One line: libpq's messages continue on indented lines.
    std::string line;
    for (const char c : what) {
      if (c == '\n' || c == '\t' || c == '\r') {
        if (!line.empty() && line.back() != ' ') line += ' ';
      } else {
        line += c;
      }
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    return line;
  }

  void connect() const {
    conn_.reset();
    auto c = std::make_unique<pqxx::connection>(info_.conninfo);
    prepare(*c);
    conn_ = std::move(c);
  }

  // Runs `f` on the connection, again after a serialization failure or a deadlock (another
  // writer's transaction won), and after a lost connection -- reconnecting with growing pauses
  // for up to window_ (a server restart). Any other error is a StatsError.
  template <class F>
  auto with_retry(const char* what, F&& f) const -> decltype(f(std::declval<pqxx::connection&>())) {
    const auto deadline = std::chrono::steady_clock::now() + window_;
    auto pause = std::chrono::milliseconds(50);
    std::string lost;
    for (int attempt = 0;; ++attempt) {
      try {
        if (!conn_ || !conn_->is_open()) connect();
        return f(*conn_);
      } catch (const RetryTransaction&) {
        if (attempt > 1000) throw StatsError(path_ + ": " + what + ": too many conflicts");
        continue;
      } catch (const pqxx::transaction_rollback& e) {  // serialization failure, deadlock
        if (attempt > 1000) throw StatsError(path_ + ": " + what + ": " + clean(e.what()));
        continue;
      } catch (const pqxx::sql_error& e) {
        if (!connection_lost(e.sqlstate())) {
          throw StatsError(path_ + ": " + what + ": " + clean(e.what()));
        }
        lost = clean(e.what());
      } catch (const pqxx::broken_connection& e) {
        lost = clean(e.what());
      } catch (const pqxx::in_doubt_error& e) {  // the COMMIT's answer was lost
        lost = clean(e.what());
      } catch (const pqxx::failure& e) {
        if (conn_ && conn_->is_open()) {
          throw StatsError(path_ + ": " + what + ": " + clean(e.what()));
        }
        lost = clean(e.what());
      }
      // The connection is gone: a new one after a pause, until the deadline.
      conn_.reset();
      if (std::chrono::steady_clock::now() + pause > deadline) {
        throw StatsError(path_ + ": " + what + ": lost the connection to the PostgreSQL server " +
                         "and could not reconnect within " +
                         std::to_string(window_.count() / 1000) + " s (LLSF_DB_RETRY_S): " + lost);
      }
      std::this_thread::sleep_for(pause);
      pause = std::min(pause * 2, std::chrono::milliseconds(2000));
    }
  }

  // SQLSTATEs that mean the session is over: connection exceptions (08), the server shutting
  // down or starting (57P01..57P03).
  static bool connection_lost(const std::string& state) {
    return state.starts_with("08") || state == "57P01" || state == "57P02" || state == "57P03";
  }

  // Brings the database to kSchemaVersion in one transaction, under an advisory lock: two
  // processes opening a new store at once create it once.
  void migrate(pqxx::connection& c) {
    pqxx::work w(c);
    w.exec("SELECT pg_advisory_xact_lock(" + std::to_string(kMigrationLock) + ")");
    int version = 0;
    if (!w.exec1("SELECT to_regclass('schema_migrations')")[0].is_null()) {
      const pqxx::row r = w.exec1("SELECT coalesce(max(version), 0) FROM schema_migrations");
      version = r[0].as<int>();
    } else {
      for (const std::string_view t : kStoreTables) {
        if (!w.exec1("SELECT to_regclass(" + w.quote(std::string(t)) + ")")[0].is_null()) {
          throw StatsError(path_ + ": not an llsfsim statistics store (it has a table '" +
                           std::string(t) + "' but no schema_migrations)");
        }
      }
    }
    if (version == kSchemaVersion) return;  // rolled back: nothing was written
    if (version > kSchemaVersion || version < 0) {
      throw StatsError(path_ + ": schema version " + std::to_string(version) +
                       " (this llsfsim reads versions up to " + std::to_string(kSchemaVersion) +
                       "; a newer llsfsim wrote it)");
    }
    for (int v = version + 1; v <= kSchemaVersion; ++v) {
      w.exec(postgres_migrations()[static_cast<std::size_t>(v - 1)]);
    }
    for (const Migration& m : kMigrations) {
      w.exec("INSERT INTO schema_migrations (version, description, applied) VALUES (" +
             std::to_string(m.version) + ", " + w.quote(std::string(m.description)) + ", " +
             (m.version > version ? std::string(kCreated) : std::string("NULL")) +
             ") ON CONFLICT (version) DO NOTHING");
    }
    w.commit();
  }

  // The statements of every operation, prepared on each new connection.
  static void prepare(pqxx::connection& c) {
    c.prepare("find_batch",
              "SELECT id FROM batches WHERE kind = $1 AND scenario_hash = $2 AND "
              "runs_per_variant = $3");
    c.prepare("insert_batch",
              "INSERT INTO batches (kind, scenario_file, scenario_name, scenario_hash, "
              "runs_per_variant, variants, seeds, llsfsim_version) VALUES ($1, $2, $3, $4, $5, "
              "$6, $7, $8) ON CONFLICT (kind, scenario_hash, runs_per_variant) DO NOTHING "
              "RETURNING id");
    c.prepare("finish_batch", std::string("UPDATE batches SET finished = ") + kCreated +
                                  " WHERE id = $1 AND finished IS NULL");
    c.prepare("remove_empty_batch",
              "DELETE FROM batches WHERE id = $1 AND NOT EXISTS (SELECT 1 FROM runs WHERE "
              "batch_id = $1)");
    c.prepare("find_run",
              "SELECT id, result_hash FROM runs WHERE batch_id = $1 AND variant = $2 AND "
              "seed = $3");
    c.prepare("delete_run", "DELETE FROM runs WHERE batch_id = $1 AND variant = $2 AND seed = $3");
    c.prepare("insert_run",
              "INSERT INTO runs (batch_id, scenario, variant, seed, llsfsim_version, result_hash, "
              "passed, points, game_time_s, cpu_s, real_time_factor, recording) VALUES ($1, $2, "
              "$3, $4, $5, $6, $7, $8, $9, $10, $11, NULLIF($12, '')) ON CONFLICT (batch_id, "
              "variant, seed) DO NOTHING RETURNING id");
    c.prepare("select_stats", "SELECT name, value FROM statistics WHERE run_id = $1 ORDER BY name");
    c.prepare("select_awards",
              "SELECT time_s, game_time_s, phase, points, reason, coalesce(device, ''), "
              "coalesce(order_id, -1), coalesce(puck, -1) FROM awards WHERE run_id = $1 "
              "ORDER BY idx");
  }

  std::vector<StoredBatch> read_batches(const std::string& where) const {
    return with_retry("reading batches", [&](pqxx::connection& c) {
      pqxx::work w(c);
      std::vector<StoredBatch> out;
      for (const pqxx::row& q :
           w.exec("SELECT id, kind, created, coalesce(finished, ''), scenario_file, "
                  "scenario_name, scenario_hash, runs_per_variant, variants, seeds FROM batches" +
                  where)) {
        StoredBatch& b = out.emplace_back();
        b.id = q[0].as<std::int64_t>();
        b.kind = q[1].as<std::string>();
        b.created = q[2].as<std::string>();
        b.finished = q[3].as<std::string>();
        b.scenario_file = q[4].as<std::string>();
        b.scenario_name = q[5].as<std::string>();
        b.scenario_hash = q[6].as<std::string>();
        b.runs_per_variant = q[7].as<int>();
        b.variants = q[8].as<int>();
        b.seeds = q[9].as<std::string>();
      }
      return out;
    });
  }

  std::vector<StoredRun> read_runs(const std::string& where) const {
    return with_retry("reading runs", [&](pqxx::connection& c) {
      pqxx::work w(c);
      std::vector<StoredRun> out;
      for (const pqxx::row& q :
           w.exec("SELECT id, batch_id, scenario, variant, seed, llsfsim_version, result_hash, "
                  "passed, points, game_time_s, cpu_s, real_time_factor, recording FROM runs " +
                  where)) {
        StoredRun& s = out.emplace_back();
        s.id = q[0].as<std::int64_t>();
        s.batch_id = q[1].as<std::int64_t>();
        s.scenario = q[2].as<std::string>();
        s.variant = q[3].as<std::string>();
        s.seed = static_cast<std::uint64_t>(q[4].as<std::int64_t>());
        s.llsfsim_version = q[5].as<std::string>();
        s.result_hash = parse_hex16(q[6].as<std::string>());
        s.passed = q[7].as<int>() != 0;
        s.points = q[8].as<int>();
        s.game_time_s = q[9].as<double>();
        s.cpu_s = q[10].as<double>();
        s.real_time_factor = q[11].as<double>();
        s.recording = q[12].is_null() ? std::string()
                                      : resolved_recording_path(path_, q[12].as<std::string>());
      }
      return out;
    });
  }

  std::string path_;  ///< the URL, its password masked
  ConnInfo info_;
  std::chrono::milliseconds window_;
  mutable std::unique_ptr<pqxx::connection> conn_;  ///< none after a loss, until reconnected
};

}  // namespace

std::unique_ptr<StatsBackend> make_postgres_backend(const std::string& url) {
  return std::make_unique<PostgresBackend>(url);
}

}  // namespace llsf::study
