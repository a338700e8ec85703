// SPDX-License-Identifier: MIT
// Benchmarks of the radio: messages per CPU second through the in-process hub with a game-like
// traffic pattern (3 robots + refbox), UDP forwarding throughput on 127.0.0.1, and a fuzz of
// hostile frames through the hub and the stream parser with its memory (issue #21).
#include <arpa/inet.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "harness.h"
#include "llsf/comm/hub.h"
#include "llsf/comm/registry.h"
#include "llsf/comm/udp_hub.h"

using namespace llsf;
using namespace llsf::comm;

namespace {

constexpr int kRepeats = 5;

llsf_agent_msgs::LockMessage lock_msg(const char* agent, const char* resource) {
  llsf_agent_msgs::LockMessage m;
  m.set_type(llsf_agent_msgs::LockMessage::GET);
  m.set_agent(agent);
  m.set_resource(resource);
  return m;
}

/// A world model of the 10 machines and 4 orders (~400 bytes): the refbox's MachineInfo-sized
/// message and the lock master's periodic broadcast.
llsf_agent_msgs::Worldmodel world_model() {
  llsf_agent_msgs::Worldmodel w;
  w.set_sender("robot1");
  w.set_seq(1);
  for (int i = 0; i < 10; ++i) {
    auto* m = w.add_machines();
    std::string name = "M";  // (not "M" + ...: GCC 12 -O3 warns falsely, -Wrestrict)
    name += std::to_string(i + 1);
    m->set_name(name);
    m->add_loaded_with(llsf_agent_msgs::S1);
    auto* in = m->add_incoming();
    in->set_action("BRING_S0");
    in->set_agent("robot2");
    m->set_junk(static_cast<unsigned>(i % 3));
  }
  for (int i = 0; i < 4; ++i) {
    auto* o = w.add_orders();
    o->set_id(static_cast<unsigned>(i + 1));
    o->set_in_delivery(0);
  }
  return w;
}

struct InprocResult {
  double msgs_per_s;
  double copies_per_s;
};

/// 3 robots and the refbox on one channel, 1 ms steps, per_link loss 10 %, 2 ms + U[0, 3] ms
/// delay. Every 1 ms each robot broadcasts a LockMessage and a WorldmodelChange; every 10 ms the
/// lock master (robot1) and the refbox each broadcast a ~400-byte Worldmodel. The receivers look
/// at every delivery (and, with `decode`, parse it). Returns per CPU second.
InprocResult hub_inproc(int steps, bool decode) {
  MessageRegistry reg;
  add_agent_messages(reg);
  HubConfig cfg;
  cfg.loss_model = LossModel::kPerLink;
  cfg.loss_probability = 0.1;
  cfg.delay.fixed = core::SimTime::from_ms(2);
  cfg.delay.jitter = core::SimTime::from_ms(3);
  Hub hub(cfg, reg, core::Rng(1));
  const PeerId robots[3] = {hub.add_peer("robot1"), hub.add_peer("robot2"), hub.add_peer("robot3")};
  const PeerId refbox = hub.add_peer("refbox", std::string(kAllChannels));
  const char* names[3] = {"robot1", "robot2", "robot3"};
  std::vector<llsf_agent_msgs::LockMessage> locks;
  std::vector<llsf_agent_msgs::WorldmodelChange> changes;
  for (int r = 0; r < 3; ++r) {
    locks.push_back(lock_msg(names[r], "M4"));
    llsf_agent_msgs::WorldmodelChange c;
    c.set_id(static_cast<unsigned>(1000 + r));
    c.set_agent(names[r]);
    c.set_change(llsf_agent_msgs::WorldmodelChange::ADD_LOADED_WITH);
    c.set_machine("M7");
    c.set_puck(llsf_agent_msgs::S1);
    changes.push_back(c);
  }
  const llsf_agent_msgs::Worldmodel wm = world_model();

  std::int64_t messages = 0, copies = 0;
  std::uint64_t checksum = 0;
  const double t0 = bench::cpu_seconds();
  for (int s = 0; s < steps; ++s) {
    const core::SimTime now = core::SimTime::from_ms(s);
    for (int r = 0; r < 3; ++r) {
      hub.broadcast(robots[r], locks[static_cast<std::size_t>(r)], now);
      hub.broadcast(robots[r], changes[static_cast<std::size_t>(r)], now);
      messages += 2;
    }
    if (s % 10 == 0) {
      hub.broadcast(robots[0], wm, now);
      hub.broadcast(refbox, wm, now);
      messages += 2;
    }
    copies += hub.step(now);
    for (int p = 0; p < hub.peer_count(); ++p) {
      for (const Delivery& d : hub.received(PeerId(p))) {
        if (decode) {
          checksum += static_cast<std::uint64_t>(hub.decode(d)->ByteSizeLong());
        } else {
          checksum += d.frame[d.frame.size() - 1];
        }
      }
    }
  }
  const double cpu = bench::cpu_seconds() - t0;
  if (checksum == 42) std::fprintf(stderr, " ");  // keep the receivers' work
  return {static_cast<double>(messages) / cpu, static_cast<double>(copies) / cpu};
}

double wall_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// A plain non-blocking UDP socket on 127.0.0.1 (the "external program").
struct RawUdp {
  RawUdp() {
    fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~RawUdp() { ::close(fd); }
  RawUdp(const RawUdp&) = delete;
  RawUdp& operator=(const RawUdp&) = delete;
  void send(const std::vector<std::uint8_t>& f, int to) const {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(to));
    ::sendto(fd, f.data(), f.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  int drain() const {
    int n = 0;
    std::uint8_t buf[2048];
    while (::recv(fd, buf, sizeof buf, 0) > 0) ++n;
    return n;
  }
  int fd;
  int port = 0;
};

/// Frames per wall second forwarded sender -> hub -> receiver on 127.0.0.1, no loss, no delay,
/// in batches of 32 (so that no socket buffer overflows).
double udp_loopback(int frames) {
  MessageRegistry reg;
  add_agent_messages(reg);
  HubConfig cfg;
  cfg.delay.fixed = core::SimTime::from_ms(0);
  RawUdp a, b;
  UdpHub hub(cfg, reg, core::Rng(1));
  const PeerId pa = hub.add_peer({"robot1", "team", 0, a.port});
  const PeerId pb = hub.add_peer({"robot2", "team", 0, b.port});
  const auto frame = reg.encode(lock_msg("robot1", "M4"));
  const TrafficCounters& link = hub.hub().link_counters(pa, pb);
  int received = 0;
  const double t0 = wall_seconds();
  const double give_up = t0 + 30.0;
  for (int sent = 0; sent < frames && wall_seconds() < give_up;) {
    for (int i = 0; i < 32 && sent < frames; ++i, ++sent) a.send(frame, hub.listen_port(pa));
    while (link.sent < sent && wall_seconds() < give_up) hub.poll();
    received += b.drain();
  }
  while (received < link.delivered && wall_seconds() < give_up) received += b.drain();
  const double wall = wall_seconds() - t0;
  return received / wall;
}

}  // namespace

LLSF_BENCH(hub_inproc, "in-process hub: 3 robots + refbox, 1 ms steps, 10% per_link loss, jitter") {
  constexpr int kSteps = 200000;  // 200 s of simulated time, ~1.2 M messages
  InprocResult last{};
  const double mps = bench::median_of(kRepeats, [&] {
    last = hub_inproc(kSteps, false);
    return last.msgs_per_s;
  });
  bench::report("hub_inproc", "msgs_per_s", mps, "1/s");
  bench::report("hub_inproc", "copies_delivered_per_s", last.copies_per_s, "1/s");
  bench::report("hub_inproc", "ns_per_msg", 1e9 / mps, "ns");
  const double with_decode =
      bench::median_of(kRepeats, [&] { return hub_inproc(kSteps, true).msgs_per_s; });
  bench::report("hub_inproc", "msgs_per_s_receivers_decode", with_decode, "1/s");
}

LLSF_BENCH(hub_udp, "UDP hub on 127.0.0.1: frames per wall second sender -> hub -> receiver") {
  const double fps = bench::median_of(kRepeats, [] { return udp_loopback(50000); });
  bench::report("hub_udp", "msgs_per_s", fps, "1/s");
}

// ---------------------------------------------------------------------------------------------
// comm_fuzz: hostile frames through the hub and the stream parser

namespace {

/// A field of /proc/self/status in kB ("VmRSS", "VmHWM"); 0 if unreadable.
long proc_status_kb(const std::string& key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1));
  }
  return 0;
}

/// Random and mutated frames from a few valid seeds: bit flips, truncation, trailing bytes,
/// random size fields (up to 4 GiB), random (component, type) pairs, pure noise.
class FrameFuzzer {
 public:
  FrameFuzzer(const MessageRegistry& reg, std::uint64_t seed) : rng_(seed) {
    seeds_.push_back(reg.encode(lock_msg("R1", "M1")));
    seeds_.push_back(reg.encode(lock_msg("robot2", "deliver")));
    seeds_.push_back(reg.encode(world_model()));
  }
  const std::vector<std::uint8_t>& next() {
    const auto& base = seeds_[pick(seeds_.size())];
    out_.assign(base.begin(), base.end());
    switch (pick(7)) {
      case 0:  // valid as is
        break;
      case 1:  // byte flips
        for (std::size_t i = 0, n = 1 + pick(4); i < n; ++i) {
          out_[pick(out_.size())] = static_cast<std::uint8_t>(rng_());
        }
        break;
      case 2:  // truncated (also below the header)
        out_.resize(pick(out_.size()));
        break;
      case 3:  // trailing garbage
        for (std::size_t i = 0, n = 1 + pick(64); i < n; ++i) {
          out_.push_back(static_cast<std::uint8_t>(rng_()));
        }
        break;
      case 4: {  // a random size field; every eighth one huge
        const std::uint32_t size = pick(8) == 0 ? static_cast<std::uint32_t>(rng_())
                                                : static_cast<std::uint32_t>(pick(2048));
        out_[4] = static_cast<std::uint8_t>(size >> 24);
        out_[5] = static_cast<std::uint8_t>(size >> 16);
        out_[6] = static_cast<std::uint8_t>(size >> 8);
        out_[7] = static_cast<std::uint8_t>(size);
        break;
      }
      case 5:  // a random (component, type)
        for (int i = 0; i < 4; ++i)
          out_[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(rng_());
        break;
      default:  // noise
        out_.resize(pick(1100));
        for (auto& b : out_) b = static_cast<std::uint8_t>(rng_());
        break;
    }
    return out_;
  }
  std::size_t pick(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng_() % n); }

 private:
  std::mt19937_64 rng_;
  std::vector<std::vector<std::uint8_t>> seeds_;
  std::vector<std::uint8_t> out_;
};

}  // namespace

LLSF_BENCH(comm_fuzz,
           "hostile input: 1,000,000 random/mutated frames through the hub and 1,000,000 through "
           "the stream parser; no crash, memory flat") {
  constexpr int kFrames = 1000000;
  MessageRegistry reg;
  add_agent_messages(reg);
  const long rss_start = proc_status_kb("VmRSS");

  // The hub: 4 peers on one channel, per_link loss, delay with jitter; a step every 100 frames.
  HubConfig cfg;
  cfg.loss_model = LossModel::kPerLink;
  cfg.loss_probability = 0.1;
  cfg.delay.fixed = SimTime::from_ms(2);
  cfg.delay.jitter = SimTime::from_ms(3);
  Hub hub(cfg, reg, core::Rng(21));
  for (const char* name : {"robot1", "robot2", "robot3", "refbox"}) hub.add_peer(name);
  FrameFuzzer hub_fuzz(reg, 1);
  std::int64_t accepted = 0;
  long rss_hub_half = 0;
  const double t0 = bench::cpu_seconds();
  for (int i = 0; i < kFrames; ++i) {
    const SimTime now = SimTime::from_ns(std::int64_t{i} * 10000);  // 100 frames per ms
    accepted += hub.broadcast_frame(PeerId(i % 4), hub_fuzz.next(), now) == FrameError::kNone;
    if (i % 100 == 99) hub.step(now);
    if (i == kFrames / 2) rss_hub_half = proc_status_kb("VmRSS");
  }
  hub.step(SimTime::from_ms(std::int64_t{1} << 30));
  const double hub_s = bench::cpu_seconds() - t0;
  const long rss_after_hub = proc_status_kb("VmRSS");

  // The stream parser: the fuzzed frames back to back, fed in random chunks (1 to 4096 bytes, as
  // reads return them); an oversized header ends the "connection" and a new decoder starts.
  FrameFuzzer stream_fuzz(reg, 2);
  std::mt19937_64 split(3);
  auto decoder = std::make_unique<StreamDecoder>();
  std::int64_t decoded = 0, refused = 0, closed = 0;
  std::vector<std::uint8_t> pending;
  long rss_stream_half = 0;
  const double t1 = bench::cpu_seconds();
  for (int i = 0; i < kFrames; ++i) {
    const auto& f = stream_fuzz.next();
    pending.insert(pending.end(), f.begin(), f.end());
    std::size_t at = 0;
    while (at < pending.size()) {
      const std::size_t n = std::min<std::size_t>(pending.size() - at, 1 + split() % 4096);
      decoder->feed(std::span<const std::uint8_t>(pending.data() + at, n));
      at += n;
      for (;;) {
        const StreamDecoder::Next next = decoder->next();
        if (next.status == StreamDecoder::Next::Status::kNeedMore) break;
        if (next.status == StreamDecoder::Next::Status::kOversized) {
          ++closed;
          decoder = std::make_unique<StreamDecoder>();
          break;
        }
        const MessageRegistry::Decoded d = reg.decode(next.frame);
        if (d.error == FrameError::kNone) {
          ++decoded;
        } else {
          ++refused;
        }
      }
    }
    pending.clear();
    if (i == kFrames / 2) rss_stream_half = proc_status_kb("VmRSS");
  }
  const double stream_s = bench::cpu_seconds() - t1;
  const long rss_end = proc_status_kb("VmRSS");

  bench::report("comm_fuzz", "hub_frames", kFrames, "frames");
  bench::report("comm_fuzz", "hub_accepted", static_cast<double>(accepted), "frames");
  bench::report("comm_fuzz", "hub_frames_per_s", kFrames / hub_s, "1/s");
  bench::report("comm_fuzz", "hub_frame_pool", hub.frame_pool_size(), "frames");
  bench::report("comm_fuzz", "stream_frames", kFrames, "frames");
  bench::report("comm_fuzz", "stream_decoded", static_cast<double>(decoded), "frames");
  bench::report("comm_fuzz", "stream_refused", static_cast<double>(refused), "frames");
  bench::report("comm_fuzz", "stream_oversized_closes", static_cast<double>(closed), "closes");
  bench::report("comm_fuzz", "stream_frames_per_s", kFrames / stream_s, "1/s");
  bench::report("comm_fuzz", "rss_start_kb", static_cast<double>(rss_start), "kB");
  bench::report("comm_fuzz", "rss_hub_half_kb", static_cast<double>(rss_hub_half), "kB");
  bench::report("comm_fuzz", "rss_after_hub_kb", static_cast<double>(rss_after_hub), "kB");
  bench::report("comm_fuzz", "rss_stream_half_kb", static_cast<double>(rss_stream_half), "kB");
  bench::report("comm_fuzz", "rss_end_kb", static_cast<double>(rss_end), "kB");
  bench::report("comm_fuzz", "peak_rss_kb", static_cast<double>(proc_status_kb("VmHWM")), "kB");
}
