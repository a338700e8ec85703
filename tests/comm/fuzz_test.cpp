// SPDX-License-Identifier: MIT
// Seeded random bytes against the decoders: 100,000 datagrams and a 100,000-chunk byte stream,
// half pure noise and half mutated valid frames. Nothing may crash, hang or contradict itself.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <vector>

#include "llsf/comm/frame.h"
#include "llsf/comm/hub.h"
#include "llsf/comm/registry.h"
#include "llsf/core/rng.h"

using namespace llsf::comm;
using llsf::core::RandomStream;
using Bytes = std::vector<std::uint8_t>;

namespace {

std::vector<Bytes> valid_frames(const MessageRegistry& r) {
  std::vector<Bytes> out;
  llsf_agent_msgs::LockMessage l;
  l.set_type(llsf_agent_msgs::LockMessage::RELEASE);
  l.set_agent("R2");
  l.set_resource("M10");
  out.push_back(r.encode(l));
  llsf_agent_msgs::WorldmodelChange c;
  c.set_id(77);
  c.set_agent("R1");
  c.set_change(llsf_agent_msgs::WorldmodelChange::ADD_INCOMING);
  c.set_machine("M2");
  c.mutable_incoming()->set_action("BRING_S0");
  c.mutable_incoming()->set_agent("R1");
  out.push_back(r.encode(c));
  llsf_agent_msgs::Worldmodel w;
  w.set_sender("R1");
  w.set_seq(1);
  for (int i = 0; i < 10; ++i) {
    auto* m = w.add_machines();
    std::string name = "M";
    name += std::to_string(i + 1);
    m->set_name(name);
    m->add_loaded_with(llsf_agent_msgs::S1);
    m->set_junk(static_cast<unsigned>(i));
  }
  out.push_back(r.encode(w));
  return out;
}

/// Random noise (any length 0..1100), or a valid frame with random byte flips, truncation or
/// extension, with the header left intact half of the time so that payload parsing is reached.
Bytes random_input(RandomStream& rng, const std::vector<Bytes>& valid) {
  if (rng.uniform01() < 0.5) {
    Bytes b(static_cast<std::size_t>(rng.uniform_int(0, 1100)));
    for (auto& x : b) x = static_cast<std::uint8_t>(rng.next_u64());
    return b;
  }
  Bytes b = valid[static_cast<std::size_t>(rng.uniform_int(0, static_cast<int>(valid.size()) - 1))];
  const bool keep_header = rng.uniform01() < 0.5;
  const int flips = static_cast<int>(rng.uniform_int(1, 4));
  for (int i = 0; i < flips; ++i) {
    const auto lo = keep_header ? std::int64_t{8} : std::int64_t{0};
    if (static_cast<std::int64_t>(b.size()) <= lo) break;
    b[static_cast<std::size_t>(rng.uniform_int(lo, static_cast<std::int64_t>(b.size()) - 1))] =
        static_cast<std::uint8_t>(rng.next_u64());
  }
  const double u = rng.uniform01();
  if (u < 0.15) {
    b.resize(static_cast<std::size_t>(rng.uniform_int(0, static_cast<std::int64_t>(b.size()))));
  } else if (u < 0.25) {
    b.push_back(static_cast<std::uint8_t>(rng.next_u64()));
  }
  return b;
}

}  // namespace

TEST_CASE("fuzz: 100,000 random datagrams through decode_datagram and the hub") {
  MessageRegistry r;
  add_agent_messages(r);
  const std::vector<Bytes> valid = valid_frames(r);
  llsf::core::Rng seeds(20130625);
  RandomStream rng = seeds.stream("test/fuzz/datagram");
  Hub hub(HubConfig{}, r, seeds);
  const PeerId a = hub.add_peer("fuzzer");
  const PeerId b = hub.add_peer("listener");

  constexpr int kInputs = 100000;
  int accepted = 0;
  std::array<int, kFrameErrorCount> by_error{};
  for (int i = 0; i < kInputs; ++i) {
    const Bytes in = random_input(rng, valid);
    const auto d = r.decode_datagram(in);
    // Consistency: a message iff no error; an accepted frame re-encodes to a valid frame.
    CHECK_UNARY((d.error == FrameError::kNone) == (d.message != nullptr));
    ++by_error[static_cast<std::size_t>(d.error)];
    if (d.message) {
      ++accepted;
      CHECK_UNARY(r.decode_datagram(r.encode(*d.message)).error == FrameError::kNone);
    }
    // The hub gives the same verdict and keeps routing.
    const auto t = llsf::core::SimTime::from_ms(i);
    CHECK_UNARY(hub.broadcast_frame(a, in, t) == d.error);
    hub.step(t);
  }
  // Every input is either forwarded or counted as malformed, by its reason.
  const PeerCounters& pc = hub.peer_counters(a);
  CHECK(pc.broadcasts == accepted);
  CHECK(pc.broadcasts + pc.malformed_total() == kInputs);
  for (int e = 1; e < kFrameErrorCount; ++e) {
    CHECK(pc.malformed[static_cast<std::size_t>(e)] == by_error[static_cast<std::size_t>(e)]);
  }
  CHECK(hub.link_counters(a, b).delivered == accepted);
  // The generator reached every outcome.
  for (int e = 0; e < kFrameErrorCount; ++e) CHECK(by_error[static_cast<std::size_t>(e)] > 0);
}

TEST_CASE("fuzz: a long stream of random chunks through StreamDecoder") {
  MessageRegistry r;
  add_agent_messages(r);
  const std::vector<Bytes> valid = valid_frames(r);
  RandomStream rng = llsf::core::Rng(7).stream("test/fuzz/stream");
  int frames = 0;
  int restarts = 0;
  StreamDecoder d(4096);
  for (int i = 0; i < 100000; ++i) {
    Bytes chunk = random_input(rng, valid);
    // Feed it in random pieces.
    std::size_t pos = 0;
    while (pos < chunk.size()) {
      const auto n = static_cast<std::size_t>(
          rng.uniform_int(1, static_cast<std::int64_t>(chunk.size() - pos)));
      d.feed(std::span(chunk.data() + pos, n));
      pos += n;
      for (;;) {
        const auto next = d.next();
        if (next.status == StreamDecoder::Next::Status::kNeedMore) break;
        if (next.status == StreamDecoder::Next::Status::kOversized) {
          // What a connection does: close, and a new one starts clean.
          ++restarts;
          d = StreamDecoder(4096);
          break;
        }
        ++frames;
        CHECK(next.frame.header.payload_size <= 4096);
        const auto dec = r.decode(next.frame);
        CHECK_UNARY((dec.error == FrameError::kNone) == (dec.message != nullptr));
      }
    }
    CHECK(d.buffered() <= 8 + 4096);
  }
  CHECK(frames > 0);
  CHECK(restarts > 0);
}
