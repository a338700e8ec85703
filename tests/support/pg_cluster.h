// SPDX-License-Identifier: MIT
// A throwaway PostgreSQL 15 cluster for tests: initdb in a fresh temporary directory, the server
// on 127.0.0.1 at a free port with its unix socket in that directory, trust authentication for
// the role `llsf`. Stopped and removed by the destructor, and by a watchdog process when the test
// process dies without it (a crash, a ctest timeout's kill). As root, the server runs as the
// `postgres` system user (Debian's postgresql package creates it): PostgreSQL refuses root.
// Header-only so that any test binary can use it (tests/study, tests/app, the Slurm tests).
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace llsf::test {

/// A PostgreSQL server of its own, for one test process. Not thread-safe (create databases from
/// one thread; the databases themselves may be used from any number of threads and processes).
class PgCluster {
 public:
  /// The server's binaries: $LLSF_PG_BINDIR, else Debian's PostgreSQL 15.
  static std::string bin_dir() {
    const char* d = std::getenv("LLSF_PG_BINDIR");
    return d != nullptr && *d != '\0' ? d : "/usr/lib/postgresql/15/bin";
  }

  /// initdb and start. Throws std::runtime_error with the tool's output if either fails.
  PgCluster() {
    namespace fs = std::filesystem;
    std::string tmpl = (fs::temp_directory_path() / "llsf_pg_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("pg_cluster: mkdtemp failed");
    dir_ = tmpl;
    as_root_ = ::geteuid() == 0;
    if (as_root_) {
      const passwd* pw = ::getpwnam("postgres");
      if (pw == nullptr) {
        remove_dir();
        throw std::runtime_error(
            "pg_cluster: running as root needs the 'postgres' system user (the postgresql "
            "package creates it: scripts/install-deps)");
      }
      if (::chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) {
        remove_dir();
        throw std::runtime_error("pg_cluster: cannot chown " + dir_ + " to postgres");
      }
    }
    start_watchdog();
    const auto t0 = std::chrono::steady_clock::now();
    std::string out;
    if (run(server_cmd({bin_dir() + "/initdb", "-D", data(), "-U", "llsf", "-A", "trust", "-E",
                        "UTF8", "--no-sync", "--no-instructions"}),
            out) != 0) {
      remove_dir();
      throw std::runtime_error("pg_cluster: initdb failed:\n" + out);
    }
    initdb_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // A free port: one the kernel hands out now; taken by someone else meanwhile, try another.
    for (int attempt = 0;; ++attempt) {
      port_ = free_port();
      if (start(out)) break;
      if (attempt == 4) {
        remove_dir();
        throw std::runtime_error("pg_cluster: the server does not start:\n" + out + log());
      }
    }
    started_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  ~PgCluster() {
    std::string out;
    if (running_)
      run(server_cmd({bin_dir() + "/pg_ctl", "-D", data(), "-m", "immediate", "-w", "stop"}), out);
    remove_dir();
    if (watchdog_write_ >= 0) ::close(watchdog_write_);  // the watchdog finds nothing left
    if (watchdog_pid_ > 0) ::waitpid(watchdog_pid_, nullptr, 0);
  }
  PgCluster(const PgCluster&) = delete;
  PgCluster& operator=(const PgCluster&) = delete;

  /// One cluster for the whole test binary, started on first use.
  static PgCluster& shared() {
    static std::unique_ptr<PgCluster> cluster;
    static std::mutex mutex;
    const std::lock_guard<std::mutex> lock(mutex);
    if (!cluster) cluster = std::make_unique<PgCluster>();
    return *cluster;
  }

  int port() const { return port_; }
  const std::string& dir() const { return dir_; }
  /// Seconds initdb took; seconds until the server accepted connections (initdb included).
  double initdb_seconds() const { return initdb_s_; }
  double startup_seconds() const { return started_s_; }

  /// The URL of database `db` (the role llsf, no password).
  std::string url(const std::string& db = "postgres") const {
    return "postgresql://llsf@127.0.0.1:" + std::to_string(port_) + "/" + db;
  }

  /// A new empty database (t1, t2, ...); returns its URL.
  std::string create_database() {
    const std::string name = "t" + std::to_string(++databases_);
    psql("postgres", "CREATE DATABASE " + name);
    return url(name);
  }

  /// Runs `sql` in database `db` with psql; returns its output (unaligned, tuples only). Throws
  /// std::runtime_error with psql's message on an error.
  std::string psql(const std::string& db, const std::string& sql) const {
    std::string out;
    if (run({bin_dir() + "/psql", "-X", "-q", "-A", "-t", "-v", "ON_ERROR_STOP=1", "-d", url(db),
             "-c", sql},
            out) != 0) {
      throw std::runtime_error("pg_cluster: psql failed: " + sql + "\n" + out);
    }
    while (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  }

  /// Stops the server (`mode`: fast ends the sessions and rolls their transactions back;
  /// immediate is a crash).
  void stop(const std::string& mode = "fast") {
    std::string out;
    if (run(server_cmd({bin_dir() + "/pg_ctl", "-D", data(), "-m", mode, "-w", "stop"}), out) !=
        0) {
      throw std::runtime_error("pg_cluster: pg_ctl stop failed:\n" + out);
    }
    running_ = false;
  }
  /// Starts it again on the same port.
  void start() {
    std::string out;
    if (!start(out)) throw std::runtime_error("pg_cluster: restart failed:\n" + out + log());
  }

  /// The server's log.
  std::string log() const {
    std::ifstream f(dir_ + "/server.log");
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
  }

  /// Runs `argv` (no shell), its stdout and stderr into `out`; returns its exit status (-1 if it
  /// could not run or died of a signal).
  static int run(const std::vector<std::string>& argv, std::string& out) {
    static std::atomic<int> counter{0};
    const std::string capture =
        (std::filesystem::temp_directory_path() /
         ("llsf_pg_out_" + std::to_string(::getpid()) + "_" + std::to_string(counter++)))
            .string();
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const int fd = ::open(capture.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return -1;
    const pid_t pid = ::fork();
    if (pid == 0) {  // only async-signal-safe calls until exec
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      const int null = ::open("/dev/null", O_RDONLY);
      if (null >= 0) ::dup2(null, STDIN_FILENO);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    ::close(fd);
    int status = -1;
    if (pid > 0) {
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    std::ifstream f(capture);
    out.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    std::filesystem::remove(capture);
    if (pid < 0 || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
  }

 private:
  std::string data() const { return dir_ + "/data"; }

  // A command of the server's: as the postgres user when root.
  std::vector<std::string> server_cmd(std::vector<std::string> argv) const {
    if (as_root_) argv.insert(argv.begin(), {"/sbin/runuser", "-u", "postgres", "--"});
    return argv;
  }

  bool start(std::string& out) {
    const std::string options = "-c listen_addresses=127.0.0.1 -p " + std::to_string(port_) +
                                " -c unix_socket_directories=" + dir_ +
                                " -c fsync=off -c full_page_writes=off -c synchronous_commit=off"
                                " -c max_connections=60";
    const int rc = run(server_cmd({bin_dir() + "/pg_ctl", "-D", data(), "-l", dir_ + "/server.log",
                                   "-o", options, "-w", "-t", "30", "start"}),
                       out);
    running_ = rc == 0;
    return running_;
  }

  static int free_port() {
    const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    socklen_t len = sizeof a;
    int port = 0;
    if (s >= 0 && ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
        ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
      port = ntohs(a.sin_port);
    }
    if (s >= 0) ::close(s);
    if (port == 0) throw std::runtime_error("pg_cluster: no free port");
    return port;
  }

  // A shell in a session of its own that waits for the end of this process (EOF on a pipe whose
  // only writer is this process: O_CLOEXEC keeps it out of every child), then stops the server
  // and removes the directory. After the destructor it finds nothing left to do.
  void start_watchdog() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return;
    std::string stop = "'" + bin_dir() + "/pg_ctl' -D '" + data() + "' -m immediate -w stop";
    if (as_root_) stop = "/sbin/runuser -u postgres -- " + stop;
    const std::string script =
        "while read -r _; do :; done; " + stop + " >/dev/null 2>&1; rm -rf '" + dir_ + "'";
    const char* argv[] = {"/bin/sh", "-c", script.c_str(), nullptr};
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::setsid();
      ::dup2(fds[0], STDIN_FILENO);  // dup2 clears O_CLOEXEC on the copy
      ::execv(argv[0], const_cast<char* const*>(argv));
      ::_exit(127);
    }
    ::close(fds[0]);
    if (pid < 0) {
      ::close(fds[1]);
      return;
    }
    watchdog_pid_ = pid;
    watchdog_write_ = fds[1];
  }

  void remove_dir() {
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }

  std::string dir_;
  bool as_root_ = false;
  bool running_ = false;
  int port_ = 0;
  int databases_ = 0;
  double initdb_s_ = 0.0;
  double started_s_ = 0.0;
  pid_t watchdog_pid_ = -1;
  int watchdog_write_ = -1;
};

}  // namespace llsf::test
