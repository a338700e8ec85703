// SPDX-License-Identifier: MIT
// The stream server when peers misbehave: closes while frames are queued and written (issue #18:
// "double free detected" when a controller left with two or more frames queued), and a seeded
// stress run of controllers that connect, send partial and garbage frames and disconnect
// mid-write while the server broadcasts. Meant to run under the asan preset (`make test` does:
// ctest --preset asan-comm); every wait is bounded by count and by a wall-clock deadline, no test
// asserts on timing.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "comm/loopback.h"
#include "llsf/comm/stream.h"

using namespace llsf::comm;
using namespace llsf::comm::test;
namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

namespace {

/// A lock request whose resource is `resource` padded with `pad` bytes (a frame that takes the
/// kernel's socket buffers longer to swallow).
llsf_agent_msgs::LockMessage big_lock(const std::string& resource, int pad) {
  llsf_agent_msgs::LockMessage m = lock(0);
  m.set_resource(resource + std::string(static_cast<std::size_t>(pad), '.'));
  return m;
}

std::string resource_of(const google::protobuf::Message& m) {
  const std::string& r = dynamic_cast<const llsf_agent_msgs::LockMessage&>(m).resource();
  return r.substr(0, r.find('.'));
}

/// The server's events, gathered across polls.
struct Pump {
  explicit Pump(StreamServer& s) : server(s) {}
  StreamServer& server;
  std::vector<StreamEvent> events;
  void once(milliseconds d = milliseconds(1)) {
    server.run_for(d);
    for (auto& e : server.take_events()) events.push_back(std::move(e));
  }
  template <class Done>
  void until(Done done, std::chrono::seconds limit = std::chrono::seconds(5)) {
    const auto deadline = Clock::now() + limit;
    while (!done() && Clock::now() < deadline) once();
  }
  int count(StreamEvent::Kind kind) const {
    return static_cast<int>(std::count_if(events.begin(), events.end(),
                                          [&](const StreamEvent& e) { return e.kind == kind; }));
  }
};

/// A raw controller socket connected to `port` (blocking connect; loopback).
std::unique_ptr<tcp::socket> connect_raw(asio::io_context& io, int port) {
  auto s = std::make_unique<tcp::socket>(io);
  s->connect(tcp::endpoint(kLoopback, static_cast<unsigned short>(port)));
  s->set_option(tcp::no_delay(true));
  return s;
}

/// Closes with a TCP reset instead of a FIN (SO_LINGER 0): the server's next write fails.
void reset(tcp::socket& s) {
  boost::system::error_code ec;
  s.set_option(asio::socket_base::linger(true, 0), ec);
  s.close(ec);
}

}  // namespace

TEST_CASE("TCP: the server closes a connection with frames queued and a write completed") {
  // The first send() writes at once (the completion waits in the event loop), the others queue;
  // disconnect() drops the queue before that completion runs. The completion must not pop the
  // dropped queue (it did: pop_front on an empty deque, "double free detected").
  const MessageRegistry reg = registry();
  for (const int queued : {1, 2, 5}) {
    CAPTURE(queued);
    StreamServer server(reg, StreamServerOptions{"127.0.0.1", 0});
    Pump pump(server);
    asio::io_context io;
    const auto raw = connect_raw(io, server.port());
    pump.until([&] { return pump.count(StreamEvent::Kind::kConnected) == 1; });
    REQUIRE(pump.count(StreamEvent::Kind::kConnected) == 1);
    const ClientId client = pump.events[0].client;
    for (int i = 0; i <= queued; ++i) REQUIRE(server.send(client, lock(i)));
    server.disconnect(client);
    CHECK_FALSE(server.send(client, lock(99)));
    for (int i = 0; i < 5; ++i) pump.once();
    CHECK(pump.count(StreamEvent::Kind::kDisconnected) == 1);
    CHECK(server.client_count() == 0);
    CHECK(server.counters(client).frames_out == queued + 1);
  }
}

TEST_CASE("TCP: a controller leaves with frames queued to it (FIN, reset, half-close; rounds)") {
  // The peer's close reaches the server's read before or after write completions, in whatever
  // order the event loop takes them; with big frames some writes are still under way. A
  // half-closed peer (shutdown of its sending side: the server reads end-of-stream and closes)
  // still accepts the bytes, so the writes under way complete without error after the close.
  // Whatever the order: one kDisconnected, last; no memory error.
  const MessageRegistry reg = registry();
  StreamServer server(reg, StreamServerOptions{"127.0.0.1", 0});
  Pump pump(server);
  asio::io_context io;
  std::mt19937 rng(18);
  constexpr int kRounds = 90;
  enum class Leave { kClose, kReset, kHalfClose };
  const auto leave = [](tcp::socket& s, Leave how) {
    boost::system::error_code ec;
    if (how == Leave::kClose) s.close(ec);
    if (how == Leave::kReset) reset(s);
    if (how == Leave::kHalfClose) s.shutdown(tcp::socket::shutdown_send, ec);
  };
  for (int round = 0; round < kRounds; ++round) {
    CAPTURE(round);
    pump.events.clear();
    auto raw = connect_raw(io, server.port());
    pump.until([&] { return pump.count(StreamEvent::Kind::kConnected) == 1; });
    REQUIRE(pump.count(StreamEvent::Kind::kConnected) == 1);
    const ClientId client = pump.events[0].client;
    const auto how = static_cast<Leave>(round % 3);
    const bool leave_first = (round / 3) % 2 == 0;
    const int frames = 2 + static_cast<int>(rng() % 6);
    const int pad = (round % 5 == 4) ? 60000 : static_cast<int>(rng() % 2000);
    if (leave_first) leave(*raw, how);  // the close is in flight while the frames queue
    for (int i = 0; i < frames; ++i) server.send(client, big_lock("M" + std::to_string(i), pad));
    if (!leave_first) leave(*raw, how);
    pump.until([&] { return pump.count(StreamEvent::Kind::kDisconnected) == 1; });
    CHECK(pump.count(StreamEvent::Kind::kDisconnected) == 1);
    CHECK(pump.events.back().kind == StreamEvent::Kind::kDisconnected);
    CHECK(server.client_count() == 0);
  }
}

namespace {

/// How a decoded message is compared: its type and its fields.
std::string summary(const google::protobuf::Message& m) {
  return m.GetTypeName() + " " + m.ShortDebugString();
}

/// A controller of the stress run: a raw socket that writes whatever the run chooses, and the
/// oracle of what the server must make of those bytes (the same decoder and registry, fed the same
/// byte stream: the messages in order, until an oversized header ends the stream).
struct Controller {
  std::unique_ptr<tcp::socket> socket;
  ClientId client;     ///< the server's id; invalid if refused
  bool open = true;    ///< this side has not closed
  bool reads = false;  ///< drains what the server sends
  bool half_closed = false;
  std::vector<std::uint8_t> rest;  ///< the rest of a frame sent in parts
  StreamDecoder model;             ///< the server's decoder, fed the same bytes
  bool model_broken = false;
  std::vector<std::string> expected_in;  ///< what the server must report, in order (a prefix)
  StreamDecoder from_server;             ///< what this controller reads
  std::vector<std::string> got_out;      ///< resources read from the server

  Controller(std::unique_ptr<tcp::socket> s, std::int64_t max_payload)
      : socket(std::move(s)), model(max_payload), from_server(max_payload) {}

  /// Writes `bytes` (non-blocking) and feeds the oracle what was written. A peer gone or a full
  /// socket buffer ends the controller: it closes, as a controller whose write fails does.
  void write(const MessageRegistry& reg, const std::vector<std::uint8_t>& bytes) {
    if (!open || half_closed || bytes.empty()) return;
    boost::system::error_code ec;
    const std::size_t n = asio::write(*socket, asio::buffer(bytes), ec);
    feed(reg, std::span<const std::uint8_t>(bytes.data(), n));
    if (ec) close(false);
  }

  void feed(const MessageRegistry& reg, std::span<const std::uint8_t> bytes) {
    if (model_broken) return;
    model.feed(bytes);
    for (;;) {
      const auto next = model.next();
      if (next.status == StreamDecoder::Next::Status::kNeedMore) break;
      if (next.status == StreamDecoder::Next::Status::kOversized) {
        model_broken = true;
        break;
      }
      const auto d = reg.decode(next.frame);
      if (d.error == FrameError::kNone) expected_in.push_back(summary(*d.message));
    }
  }

  /// Reads what is there (non-blocking); every frame from the server must decode.
  void drain(const MessageRegistry& reg) {
    if (!open) return;
    std::array<std::uint8_t, 8192> buf{};
    for (int i = 0; i < 64; ++i) {
      boost::system::error_code ec;
      const std::size_t n = socket->read_some(asio::buffer(buf), ec);
      if (ec) return;
      from_server.feed(std::span<const std::uint8_t>(buf.data(), n));
      for (;;) {
        const auto next = from_server.next();
        REQUIRE(next.status != StreamDecoder::Next::Status::kOversized);
        if (next.status == StreamDecoder::Next::Status::kNeedMore) break;
        const auto d = reg.decode(next.frame);
        REQUIRE(d.error == FrameError::kNone);
        got_out.push_back(resource_of(*d.message));
      }
    }
  }

  void close(bool abortive) {
    if (!open) return;
    open = false;
    if (abortive) {
      reset(*socket);
    } else {
      boost::system::error_code ec;
      socket->close(ec);
    }
  }
};

/// Garbage that keeps the framing (the server skips the frame) or breaks it.
std::vector<std::uint8_t> garbage(const MessageRegistry& reg, std::mt19937& rng, int n) {
  std::vector<std::uint8_t> f = reg.encode(lock(n));
  const auto pick = rng() % 10;
  if (pick == 0) {  // unknown component
    f[0] = static_cast<std::uint8_t>(rng() % 256);
    f[1] = static_cast<std::uint8_t>(rng() % 256);
  } else if (pick == 1) {  // unknown message type of the agents' component
    f[2] = 0x7f;
    f[3] = static_cast<std::uint8_t>(rng() % 256);
  } else if (pick == 2) {  // truncated protobuf: the size field says so, the string is cut
    const std::size_t cut = 1 + rng() % 3;
    f.resize(f.size() - cut);
    std::array<std::uint8_t, kHeaderSize> h{};
    write_header(h, MessageKey{kAgentComponentId, 1}, static_cast<std::int64_t>(f.size()) - 8);
    std::copy(h.begin(), h.end(), f.begin());
  } else if (pick == 3) {  // garbage payload bytes
    for (std::size_t i = kHeaderSize; i < f.size(); ++i) f[i] = static_cast<std::uint8_t>(rng());
  } else if (pick == 4) {  // a size field beyond max_payload (closes the connection)
    f.resize(kHeaderSize + 4);
    f[4] = 0x7f;
    f[5] = static_cast<std::uint8_t>(rng() % 256);
  } else if (pick == 5) {  // random bytes (the stream loses its framing)
    f.assign(1 + rng() % 40, 0);
    for (auto& b : f) b = static_cast<std::uint8_t>(rng());
  } else {  // a frame cut short (the next frame's bytes complete it: garbage or a close)
    f.resize(kHeaderSize + rng() % (f.size() - kHeaderSize));
  }
  return f;
}

}  // namespace

TEST_CASE(
    "TCP stress: controllers connect, send parts and garbage, leave mid-write; server "
    "broadcasts") {
  const MessageRegistry reg = registry();
  int log_lines = 0;
  StreamServerOptions options{"127.0.0.1", 0};
  options.max_payload = 64 * 1024;
  options.max_connections = 6;
  options.max_send_queue_bytes = 96 * 1024;
  options.partial_frame_timeout = milliseconds(100);
  options.log = [&](std::string_view) { ++log_lines; };
  StreamServer server(reg, options);
  Pump pump(server);
  asio::io_context io;
  std::mt19937 rng(20130618);  // the fuzz choices; the kernel's timing is not ours to fix
  std::vector<std::unique_ptr<Controller>> controllers;
  std::map<int, std::vector<std::string>> sent_to;  ///< by client id: resources sent, in order
  std::map<int, bool> connected;                    ///< by client id, from the events
  std::size_t seen = 0;                             ///< events looked at
  const auto take = [&] {
    for (; seen < pump.events.size(); ++seen) {
      const StreamEvent& e = pump.events[seen];
      if (e.kind == StreamEvent::Kind::kConnected) connected[e.client.value()] = true;
      if (e.kind == StreamEvent::Kind::kDisconnected) connected[e.client.value()] = false;
    }
  };
  const auto live = [&] {
    std::vector<Controller*> out;
    for (auto& c : controllers) {
      if (c->open) out.push_back(c.get());
    }
    return out;
  };
  int next_resource = 0;

  constexpr int kSteps = 4000;
  for (int step = 0; step < kSteps; ++step) {
    CAPTURE(step);
    const auto action = rng() % 100;
    auto open = live();
    Controller* c = open.empty() ? nullptr : open[rng() % open.size()];
    if (action < 8 || c == nullptr) {
      // A controller connects: accepted (kConnected) or refused (beyond max_connections).
      const auto refused = server.refused_count();
      const int accepted = pump.count(StreamEvent::Kind::kConnected);
      auto ctl = std::make_unique<Controller>(connect_raw(io, server.port()), options.max_payload);
      ctl->socket->non_blocking(true);
      ctl->reads = rng() % 2 == 0;
      pump.until([&] {
        return pump.count(StreamEvent::Kind::kConnected) > accepted ||
               server.refused_count() > refused;
      });
      take();
      if (pump.count(StreamEvent::Kind::kConnected) > accepted) {
        for (auto it = pump.events.rbegin(); it != pump.events.rend(); ++it) {
          if (it->kind == StreamEvent::Kind::kConnected) {
            ctl->client = it->client;
            break;
          }
        }
      } else {
        REQUIRE(server.refused_count() > refused);
        ctl->close(false);
      }
      controllers.push_back(std::move(ctl));
    } else if (action < 30) {
      // A valid frame, whole or the first part of one (the rest comes later, or never).
      if (!c->rest.empty()) {
        const auto rest = std::move(c->rest);
        c->rest.clear();
        c->write(reg, rest);
      } else {
        const auto f = reg.encode(
            big_lock("M" + std::to_string(next_resource++), static_cast<int>(rng() % 3000)));
        const std::size_t cut = rng() % 3 == 0 ? 1 + rng() % (f.size() - 1) : f.size();
        c->write(reg, std::vector<std::uint8_t>(f.begin(), f.begin() + static_cast<long>(cut)));
        c->rest.assign(f.begin() + static_cast<long>(cut), f.end());
      }
    } else if (action < 38) {
      c->write(reg, c->rest);  // a frame's rest first, if one is open: then garbage
      c->rest.clear();
      c->write(reg, garbage(reg, rng, next_resource++));
    } else if (action < 60) {
      // The server broadcasts, sometimes frames bigger than a socket buffer swallows at once.
      const std::string r = "B" + std::to_string(next_resource++);
      const int pad = rng() % 4 == 0 ? 40000 : static_cast<int>(rng() % 1000);
      for (const auto& [id, on] : connected) {
        if (on) sent_to[id].push_back(r);
      }
      server.broadcast(big_lock(r, pad));
    } else if (action < 66) {
      if (c->client.valid()) {
        const std::string r = "S" + std::to_string(next_resource++);
        if (server.send(c->client, big_lock(r, static_cast<int>(rng() % 20000)))) {
          sent_to[c->client.value()].push_back(r);
        }
      }
    } else if (action < 76) {
      if (c->reads) c->drain(reg);
    } else if (action < 84) {
      // The controller leaves: FIN, reset or half-close, whatever the server has queued to it.
      const auto how = rng() % 3;
      if (how == 2 && !c->half_closed) {
        boost::system::error_code ec;
        c->socket->shutdown(tcp::socket::shutdown_send, ec);
        c->half_closed = true;
      } else {
        c->close(how == 1);
      }
    } else if (action < 87) {
      if (c->client.valid()) server.disconnect(c->client);
    } else {
      pump.once(milliseconds(rng() % 3));
    }
    pump.once(milliseconds(0));
    take();
  }

  // Everyone leaves; the server reports each connection closed exactly once.
  for (auto& c : controllers) {
    if (c->reads) c->drain(reg);
    c->close(rng() % 2 == 0);
  }
  pump.until([&] { return server.client_count() == 0; });
  take();
  REQUIRE(server.client_count() == 0);

  std::map<int, std::vector<const StreamEvent*>> by_client;
  for (const auto& e : pump.events) by_client[e.client.value()].push_back(&e);
  CHECK(static_cast<std::int64_t>(by_client.size()) == pump.count(StreamEvent::Kind::kConnected));
  int checked_in = 0;
  int checked_out = 0;
  for (const auto& c : controllers) {
    if (!c->client.valid()) continue;
    CAPTURE(c->client.value());
    const auto& evs = by_client[c->client.value()];
    REQUIRE(evs.size() >= 2);
    CHECK(evs.front()->kind == StreamEvent::Kind::kConnected);
    CHECK(evs.back()->kind == StreamEvent::Kind::kDisconnected);
    // What the server decoded is, in order, what the same decoder makes of the bytes sent (a
    // prefix: a close may cut it short).
    std::vector<std::string> in;
    for (std::size_t i = 1; i + 1 < evs.size(); ++i) {
      REQUIRE(evs[i]->kind == StreamEvent::Kind::kMessage);
      in.push_back(summary(*evs[i]->message));
    }
    REQUIRE(in.size() <= c->expected_in.size());
    CHECK(std::equal(in.begin(), in.end(), c->expected_in.begin()));
    const StreamCounters& counters = server.counters(c->client);
    CHECK(counters.frames_in == static_cast<std::int64_t>(in.size()));
    checked_in += static_cast<int>(in.size());
    // What a reading controller got is, in order, what was sent to it.
    const auto& out = sent_to[c->client.value()];
    REQUIRE(c->got_out.size() <= out.size());
    CHECK(std::equal(c->got_out.begin(), c->got_out.end(), out.begin()));
    CHECK(static_cast<std::int64_t>(c->got_out.size()) <= counters.frames_out);
    checked_out += static_cast<int>(c->got_out.size());
  }
  // The run did exercise the paths (counts depend on the kernel's timing; loose bounds only).
  CHECK(pump.count(StreamEvent::Kind::kConnected) > 20);
  CHECK(server.refused_count() > 0);
  CHECK(checked_in > 50);
  CHECK(checked_out > 50);
  CHECK(log_lines > 0);

  // The server still serves a well-behaved controller (the project's client).
  StreamClient client(reg);
  REQUIRE(client.connect("127.0.0.1", server.port()));
  REQUIRE(client.send(lock(7)));
  pump.until([&] {
    return !pump.events.empty() && pump.events.back().kind == StreamEvent::Kind::kMessage;
  });
  REQUIRE(pump.events.back().kind == StreamEvent::Kind::kMessage);
  CHECK(summary(*pump.events.back().message) == summary(lock(7)));
  CHECK(server.broadcast(lock(8)) == 1);
  std::vector<StreamEvent> at_client;
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (at_client.empty() && Clock::now() < deadline) {
    pump.once();
    client.run_for(milliseconds(1));
    for (auto& e : client.take_events()) at_client.push_back(std::move(e));
  }
  REQUIRE(at_client.size() == 1);
  CHECK(resource_of(*at_client[0].message) == "M8");
}

TEST_CASE("TCP: a server destroyed with connections open and frames under way") {
  const MessageRegistry reg = registry();
  asio::io_context io;
  std::vector<std::unique_ptr<tcp::socket>> raws;
  StreamClient client(reg);
  {
    StreamServer server(reg, StreamServerOptions{"127.0.0.1", 0});
    Pump pump(server);
    for (int i = 0; i < 3; ++i) raws.push_back(connect_raw(io, server.port()));
    REQUIRE(client.connect("127.0.0.1", server.port()));
    pump.until([&] { return pump.count(StreamEvent::Kind::kConnected) == 4; });
    REQUIRE(pump.count(StreamEvent::Kind::kConnected) == 4);
    // Nobody reads: frames of 200 KB fill the sockets' buffers, writes stay under way.
    for (int i = 0; i < 4; ++i)
      CHECK(server.broadcast(big_lock("M" + std::to_string(i), 200000)) == 4);
    pump.once();
    REQUIRE(client.send(lock(1)));
    // A partial frame from one of them.
    const auto f = reg.encode(lock(2));
    asio::write(*raws[0], asio::buffer(f.data(), 5));
    pump.once();
  }
  // The client sees the server go; its own queue (a frame in flight) is dropped cleanly.
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  bool gone = false;
  while (!gone && Clock::now() < deadline) {
    client.run_for(milliseconds(1));
    for (const auto& e : client.take_events()) gone |= e.kind == StreamEvent::Kind::kDisconnected;
  }
  CHECK(gone);
  CHECK_FALSE(client.connected());
}

namespace {

/// Fills the process's descriptor table (the soft limit lowered to what is open + 8, then dup()
/// until EMFILE) but for `spare` descriptors; release() or the destructor undoes it.
class DescriptorsExhausted {
 public:
  explicit DescriptorsExhausted(int spare) {
    REQUIRE(::getrlimit(RLIMIT_NOFILE, &old_) == 0);
    int highest = 2;
    for (const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) {
      highest = std::max(highest, std::stoi(e.path().filename().string()));
    }
    rlimit low = old_;
    low.rlim_cur = static_cast<rlim_t>(highest + 8);
    REQUIRE(::setrlimit(RLIMIT_NOFILE, &low) == 0);
    for (;;) {
      const int fd = ::dup(0);
      if (fd < 0) break;
      fds_.push_back(fd);
    }
    for (int i = 0; i < spare && !fds_.empty(); ++i) {
      ::close(fds_.back());
      fds_.pop_back();
    }
  }
  DescriptorsExhausted(const DescriptorsExhausted&) = delete;
  DescriptorsExhausted& operator=(const DescriptorsExhausted&) = delete;
  ~DescriptorsExhausted() { release(); }
  void release() {
    for (const int fd : fds_) ::close(fd);
    fds_.clear();
    ::setrlimit(RLIMIT_NOFILE, &old_);
  }

 private:
  rlimit old_{};
  std::vector<int> fds_;
};

}  // namespace

TEST_CASE("TCP: out of file descriptors, the server retries accepting (logged once), recovers") {
  const MessageRegistry reg = registry();
  std::vector<std::string> log;
  StreamServerOptions options{"127.0.0.1", 0};
  options.log = [&](std::string_view line) { log.emplace_back(line); };
  StreamServer server(reg, options);
  Pump pump(server);
  asio::io_context io;
  tcp::socket raw(io);
  raw.open(tcp::v4());  // the controller's descriptor (and its event loop's) taken before
  {
    DescriptorsExhausted full(0);
    // The connection waits in the listen backlog and every accept fails with EMFILE.
    raw.connect(tcp::endpoint(kLoopback, static_cast<unsigned short>(server.port())));
    for (int i = 0; i < 30; ++i) pump.once(milliseconds(10));
    CHECK(pump.count(StreamEvent::Kind::kConnected) == 0);
    full.release();
  }
  REQUIRE(log.size() == 1);
  CHECK(log[0] ==
        "stream server: cannot accept a connection: Too many open files; retrying every 100 ms "
        "until it works");
  pump.until([&] { return pump.count(StreamEvent::Kind::kConnected) == 1; });
  CHECK(pump.count(StreamEvent::Kind::kConnected) == 1);
  CHECK(log.size() == 1);
}
