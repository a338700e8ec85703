// SPDX-License-Identifier: MIT
// (f) Robustness of the 2013 llsf_msgs decoders against random and corrupted input: a network
// peer can send anything. Seeded, so every run feeds the same bytes.
#include <doctest/doctest.h>

#include <llsf/core/rng.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "refbox/msgs/wire_samples.h"

namespace {

using google::protobuf::Message;
using llsf::core::RandomStream;

// The outcome counts of one fuzz run.
struct FuzzStats {
  int parsed = 0;
  int rejected = 0;
  int broken_invariants = 0;  // a successful parse that is not initialized or not stable
};

// Parse `data` into `m`; on success the message must be complete and its encoding stable:
// serialize(parse(serialize(m))) == serialize(m). (Bytes, not MessageDifferencer: a corrupted
// float can decode to NaN, which is never equal to itself; consumers must check isfinite.)
void feed(Message& m, const std::string& data, FuzzStats& stats) {
  if (!m.ParseFromArray(data.data(), static_cast<int>(data.size()))) {
    ++stats.rejected;
    return;
  }
  ++stats.parsed;
  std::unique_ptr<Message> again(m.New());
  const std::string encoded = m.SerializeAsString();
  const bool ok =
      m.IsInitialized() && again->ParseFromString(encoded) && again->SerializeAsString() == encoded;
  if (!ok) {
    ++stats.broken_invariants;
    MESSAGE(m.GetTypeName(), " ", llsf::msgs_test::to_hex(data), " -> ", m.ShortDebugString());
  }
}

std::vector<std::unique_ptr<Message>> fuzz_targets() {
  std::vector<std::unique_ptr<Message>> t;
  t.push_back(std::make_unique<llsf_msgs::BeaconSignal>());
  t.push_back(std::make_unique<llsf_msgs::GameState>());
  t.push_back(std::make_unique<llsf_msgs::MachineInfo>());
  t.push_back(std::make_unique<llsf_msgs::RobotInfo>());
  t.push_back(std::make_unique<llsf_msgs::OrderInfo>());
  t.push_back(std::make_unique<llsf_msgs::MachineReport>());
  t.push_back(std::make_unique<llsf_msgs::SyncInfo>());
  t.push_back(std::make_unique<llsf_msgs::SetPucks>());
  t.push_back(std::make_unique<llsf_log_msgs::LogMessage>());
  return t;
}

TEST_CASE("msgs: 100,000 random byte strings never crash a decoder") {
  const google::protobuf::LogSilencer quiet;  // most inputs are rejected, by design
  RandomStream rng(0x11f5'2013);
  auto targets = fuzz_targets();
  FuzzStats stats;
  constexpr int kInputs = 100'000;
  std::string data;
  for (int i = 0; i < kInputs; ++i) {
    // Lengths up to 1024 bytes (the UDP receive buffer, §9.2), mostly short.
    const auto len = rng.bernoulli(0.9) ? rng.uniform_int(0, 48) : rng.uniform_int(49, 1024);
    data.resize(static_cast<std::size_t>(len));
    for (auto& c : data) c = static_cast<char>(rng.next_u64() & 0xff);
    feed(*targets[static_cast<std::size_t>(i) % targets.size()], data, stats);
  }
  CHECK(stats.parsed + stats.rejected == kInputs);
  CHECK(stats.broken_invariants == 0);
  // Both outcomes happen: messages without required fields accept some random strings.
  CHECK(stats.parsed > 0);
  CHECK(stats.rejected > kInputs / 2);
}

TEST_CASE("msgs: 100,000 corrupted valid messages never crash a decoder") {
  const google::protobuf::LogSilencer quiet;
  RandomStream rng(0x11f5'2014);
  const auto& all = llsf::msgs_test::samples();
  FuzzStats stats;
  constexpr int kInputs = 100'000;
  for (int i = 0; i < kInputs; ++i) {
    const auto& s = all[static_cast<std::size_t>(
        rng.uniform_int(0, static_cast<std::int64_t>(all.size()) - 1))];
    std::string data = s.expected;
    // 1..4 edits: flip a bit, overwrite a byte, insert a byte, delete a byte, or truncate.
    const auto edits = rng.uniform_int(1, 4);
    for (std::int64_t e = 0; e < edits; ++e) {
      const auto size = static_cast<std::int64_t>(data.size());
      const auto pos = static_cast<std::size_t>(rng.uniform_int(0, size > 0 ? size - 1 : 0));
      const auto byte = static_cast<char>(rng.next_u64() & 0xff);
      switch (rng.uniform_int(0, 4)) {
        case 0:
          if (!data.empty())
            data[pos] = static_cast<char>(data[pos] ^ (1 << rng.uniform_int(0, 7)));
          break;
        case 1:
          if (!data.empty()) data[pos] = byte;
          break;
        case 2:
          data.insert(data.begin() + static_cast<std::ptrdiff_t>(pos), byte);
          break;
        case 3:
          if (!data.empty()) data.erase(pos, 1);
          break;
        default:
          data.resize(pos);
          break;
      }
    }
    std::unique_ptr<Message> m(s.make()->New());
    feed(*m, data, stats);
  }
  CHECK(stats.parsed + stats.rejected == kInputs);
  CHECK(stats.broken_invariants == 0);
  CHECK(stats.parsed > kInputs / 20);
  CHECK(stats.rejected > kInputs / 20);
}

}  // namespace
