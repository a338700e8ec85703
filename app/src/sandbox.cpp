// SPDX-License-Identifier: MIT
// run_sandboxed: fork + exec with limits (sandbox.h). Between fork and exec the child calls only
// async-signal-safe functions: the parent may have other threads holding locks.
#include "sandbox.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>

namespace llsf::app {

namespace {

/// A file descriptor closed on destruction.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  void reset(int fd = -1) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
  }

 private:
  int fd_ = -1;
};

bool make_pipe(Fd& read_end, Fd& write_end) {
  std::array<int, 2> fds{};
  if (::pipe2(fds.data(), O_CLOEXEC) != 0) return false;
  read_end.reset(fds[0]);
  write_end.reset(fds[1]);
  return true;
}

void set_limit(int resource, rlim_t soft, rlim_t hard) {
  const rlimit l{soft, hard};
  ::setrlimit(resource, &l);
}

/// The child's side: never returns.
[[noreturn]] void exec_child(char* const* argv, const char* cwd, int out_fd, int err_fd,
                             int null_fd, int status_fd, const SandboxLimits& limits) {
  ::setpgid(0, 0);
  // Signals as a fresh process has them (the server's threads block SIGINT/SIGTERM; exec keeps
  // the mask and ignored dispositions).
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  for (const int s : {SIGPIPE, SIGINT, SIGTERM, SIGHUP, SIGXCPU, SIGXFSZ}) {
    ::sigaction(s, &dfl, nullptr);
  }
  ::dup2(null_fd, 0);
  ::dup2(out_fd, 1);
  ::dup2(err_fd, 2);
  // No descriptor of the server (sockets, the database) reaches the worker; status_fd is
  // close-on-exec and reports an exec failure.
  if (status_fd > 3) ::close_range(3, static_cast<unsigned>(status_fd) - 1, 0);
  ::close_range(static_cast<unsigned>(status_fd) + 1, ~0U, 0);
  int err = 0;
  if (::chdir(cwd) != 0) {
    err = errno;
  } else {
    const auto cpu = static_cast<rlim_t>(limits.cpu_s);
    set_limit(RLIMIT_CPU, cpu, cpu + 1);
    const auto as = static_cast<rlim_t>(limits.address_space_bytes);
    set_limit(RLIMIT_AS, as, as);
    const auto fsize = static_cast<rlim_t>(limits.file_size_bytes);
    set_limit(RLIMIT_FSIZE, fsize, fsize);
    set_limit(RLIMIT_CORE, 0, 0);
    ::execv(argv[0], argv);
    err = errno;
  }
  const ssize_t ignored = ::write(status_fd, &err, sizeof err);
  static_cast<void>(ignored);
  ::_exit(127);
}

/// Appends what `fd` has to `buf` up to `cap` (the rest is read and dropped); false at EOF.
bool drain(int fd, std::string& buf, std::int64_t cap, bool& truncated) {
  std::array<char, 65536> chunk{};
  const ssize_t n = ::read(fd, chunk.data(), chunk.size());
  if (n == 0) return false;
  if (n < 0) return errno == EINTR || errno == EAGAIN;
  const auto room = static_cast<std::size_t>(
      std::max<std::int64_t>(0, cap - static_cast<std::int64_t>(buf.size())));
  const auto take = std::min(room, static_cast<std::size_t>(n));
  buf.append(chunk.data(), take);
  if (take < static_cast<std::size_t>(n)) truncated = true;
  return true;
}

}  // namespace

SandboxResult run_sandboxed(const std::vector<std::string>& argv, const std::string& cwd,
                            const SandboxLimits& limits, const std::function<bool()>& cancel) {
  SandboxResult r;
  const auto t0 = std::chrono::steady_clock::now();
  if (argv.empty()) {
    r.error = "no program to run";
    return r;
  }
  // Everything the child needs, prepared before fork (no allocation after it).
  std::vector<std::string> args = argv;
  std::vector<char*> cargv;
  cargv.reserve(args.size() + 1);
  for (std::string& a : args) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  Fd out_r;
  Fd out_w;
  Fd err_r;
  Fd err_w;
  Fd status_r;
  Fd status_w;
  if (!make_pipe(out_r, out_w) || !make_pipe(err_r, err_w) || !make_pipe(status_r, status_w)) {
    r.error = std::string("cannot create a pipe: ") + std::strerror(errno);
    return r;
  }
  const Fd null_fd(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  const pid_t pid = ::fork();
  if (pid < 0) {
    r.error = std::string("cannot fork: ") + std::strerror(errno);
    return r;
  }
  if (pid == 0) {
    exec_child(cargv.data(), cwd.c_str(), out_w.get(), err_w.get(), null_fd.get(), status_w.get(),
               limits);
  }
  ::setpgid(pid, pid);  // also here: no race with the kill below
  out_w.reset();
  err_w.reset();
  status_w.reset();

  // Did exec work? The status pipe closes on exec (EOF) or carries the child's errno.
  int child_errno = 0;
  ssize_t got = 0;
  do {
    got = ::read(status_r.get(), &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR);
  if (got == static_cast<ssize_t>(sizeof child_errno)) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    r.error = "cannot run " + argv[0] + " (in " + cwd + "): " + std::strerror(child_errno);
    return r;
  }
  r.started = true;

  // Read both streams until they close and the child has exited, the wall limit or a cancel.
  const auto deadline = t0 + std::chrono::duration<double>(limits.wall_s);
  bool out_open = true;
  bool err_open = true;
  bool exited = false;
  int status = 0;
  auto kill_group = [&] {
    ::kill(-pid, SIGKILL);
    ::kill(pid, SIGKILL);
  };
  for (;;) {
    if (!exited) {
      const pid_t w = ::waitpid(pid, &status, WNOHANG);
      if (w == pid) exited = true;
    }
    if (exited && !out_open && !err_open) break;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline && !r.timed_out) {
      r.timed_out = true;
      kill_group();
    }
    if (cancel && !r.cancelled && cancel()) {
      r.cancelled = true;
      kill_group();
    }
    if (exited && (r.timed_out || r.cancelled)) break;
    if (exited) {
      // The worker is gone; whatever of its group still holds the pipes goes with it.
      kill_group();
    }
    std::array<pollfd, 2> fds{};
    int n = 0;
    if (out_open) fds[static_cast<std::size_t>(n++)] = {out_r.get(), POLLIN, 0};
    if (err_open) fds[static_cast<std::size_t>(n++)] = {err_r.get(), POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now);
    const int wait_ms = static_cast<int>(std::clamp<std::int64_t>(left.count(), 0, 50));
    if (n == 0) {
      ::poll(nullptr, 0, wait_ms);
      continue;
    }
    if (::poll(fds.data(), static_cast<nfds_t>(n), wait_ms) <= 0) continue;
    for (int i = 0; i < n; ++i) {
      const pollfd& p = fds[static_cast<std::size_t>(i)];
      if ((p.revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
      if (p.fd == out_r.get()) {
        out_open = drain(p.fd, r.out, limits.max_output_bytes, r.out_truncated);
      } else {
        err_open = drain(p.fd, r.err, limits.max_output_bytes, r.err_truncated);
      }
    }
  }
  if (!exited) ::waitpid(pid, &status, 0);
  ::kill(-pid, SIGKILL);  // a grandchild left behind
  if (WIFEXITED(status)) {
    r.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.signal = WTERMSIG(status);
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace llsf::app
