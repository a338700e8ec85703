// SPDX-License-Identifier: MIT
// The 2013 llsf_msgs on the wire: (b) hand-computed bytes, (c) round trips, (d) required fields,
// and the decoding cases a 2013 peer produces (unpacked/packed repeated fields, unknown enum
// values, unknown fields, 0.5.x beacons).
#include <doctest/doctest.h>
#include <google/protobuf/util/message_differencer.h>

#include <cmath>
#include <memory>
#include <set>
#include <string>

#include "refbox/msgs/wire_samples.h"

namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::util::MessageDifferencer;
using llsf::msgs_test::all_message_types;
using llsf::msgs_test::bytes;
using llsf::msgs_test::samples;
using llsf::msgs_test::set_time;
using llsf::msgs_test::to_hex;

TEST_CASE("msgs: bytes() reads hex pairs and quoted text, and rejects malformed input") {
  CHECK(bytes(R"(0a 02 "M1" ff)") == std::string("\x0a\x02M1\xff", 5));
  CHECK(bytes("") == "");
  CHECK(to_hex(bytes("00 7f 80 FF")) == "00 7f 80 ff");
  CHECK_THROWS_AS(bytes("0"), std::invalid_argument);
  CHECK_THROWS_AS(bytes("0 1"), std::invalid_argument);
  CHECK_THROWS_AS(bytes("zz"), std::invalid_argument);
  CHECK_THROWS_AS(bytes(R"("open)"), std::invalid_argument);
}

TEST_CASE("msgs: every message type has a sample") {
  std::set<std::string> sampled;
  for (const auto& s : samples()) sampled.insert(s.make()->GetDescriptor()->full_name());
  for (const auto* d : all_message_types())
    CHECK_MESSAGE(sampled.count(d->full_name()) == 1, d->full_name());
  CHECK(sampled.size() == all_message_types().size());
}

TEST_CASE("msgs: every sample serializes to its hand-computed bytes") {
  for (const auto& s : samples()) {
    CAPTURE(s.label);
    const auto m = s.make();
    REQUIRE(m->IsInitialized());
    CHECK(to_hex(m->SerializeAsString()) == to_hex(s.expected));
    CHECK(m->ByteSizeLong() == s.expected.size());
    // One UDP datagram holds at most 1024 bytes (§9.2); the samples are far below.
    CHECK(s.expected.size() + 8 <= 1024);
  }
}

TEST_CASE("msgs: every sample survives parse(serialize(m))") {
  for (const auto& s : samples()) {
    CAPTURE(s.label);
    const auto m = s.make();
    std::unique_ptr<Message> parsed(m->New());
    REQUIRE(parsed->ParseFromString(m->SerializeAsString()));
    CHECK(MessageDifferencer::Equals(*parsed, *m));
    CHECK(parsed->SerializeAsString() == m->SerializeAsString());
    // Parsing the hand-written bytes gives the same message, and no unknown fields.
    std::unique_ptr<Message> from_hand(m->New());
    REQUIRE(from_hand->ParseFromString(s.expected));
    CHECK(MessageDifferencer::Equals(*from_hand, *m));
    CHECK(from_hand->GetReflection()->GetUnknownFields(*from_hand).empty());
  }
}

TEST_CASE("msgs: a missing required field makes the message uninitialized and unparseable") {
  const google::protobuf::LogSilencer quiet;  // the parse failures are expected
  std::set<std::string> exercised;            // "Message.field"
  for (const auto& s : samples()) {
    const auto full = s.make();
    const auto* d = full->GetDescriptor();
    for (int i = 0; i < d->field_count(); ++i) {
      const FieldDescriptor* f = d->field(i);
      if (!f->is_required()) continue;
      CAPTURE(s.label);
      CAPTURE(f->name());
      exercised.insert(d->full_name() + "." + f->name());
      std::unique_ptr<Message> m(full->New());
      m->CopyFrom(*full);
      m->GetReflection()->ClearField(m.get(), f);
      CHECK(!m->IsInitialized());
      CHECK(m->InitializationErrorString() == f->name());
      const std::string partial = m->SerializePartialAsString();
      std::unique_ptr<Message> parsed(full->New());
      CHECK(!parsed->ParseFromString(partial));
      CHECK(parsed->ParsePartialFromString(partial));
    }
  }
  // Every required field of every message type was taken away once.
  int required_fields = 0;
  for (const auto* d : all_message_types()) {
    for (int i = 0; i < d->field_count(); ++i) {
      if (!d->field(i)->is_required()) continue;
      ++required_fields;
      const std::string name = d->full_name() + "." + d->field(i)->name();
      CHECK_MESSAGE(exercised.count(name) == 1, name);
    }
  }
  CHECK(required_fields == static_cast<int>(exercised.size()));
}

TEST_CASE("msgs: required fields inside sub-messages count too") {
  const google::protobuf::LogSilencer quiet;  // the parse failures are expected
  using namespace llsf_msgs;
  SUBCASE("BeaconSignal whose pose lacks its timestamp") {
    BeaconSignal m;
    set_time(m.mutable_time(), 1, 0);
    m.set_seq(1);
    m.set_team_name("T");
    m.set_peer_name("P");
    m.set_number(1);
    CHECK(m.IsInitialized());
    m.mutable_pose()->set_x(1.0f);
    m.mutable_pose()->set_y(1.0f);
    m.mutable_pose()->set_ori(1.0f);
    CHECK(!m.IsInitialized());
    CHECK(m.InitializationErrorString() == "pose.timestamp");
    BeaconSignal parsed;
    CHECK(!parsed.ParseFromString(m.SerializePartialAsString()));
  }
  SUBCASE("Robot whose last_seen lacks nsec, by hand: 22 02 08 05") {
    // name, team, host, number set; last_seen = {sec 5} only.
    const std::string wire = bytes(R"(0a 01 "r" 12 01 "t" 1a 01 "h" 22 02 08 05 38 01)");
    Robot parsed;
    CHECK(!parsed.ParseFromString(wire));
    CHECK(parsed.ParsePartialFromString(wire));
    CHECK(parsed.InitializationErrorString() == "last_seen.nsec");
  }
  SUBCASE("MachineInfo with a Machine without name") {
    MachineInfo m;
    m.add_machines()->set_type("T1");
    CHECK(!m.IsInitialized());
    MachineInfo parsed;
    CHECK(!parsed.ParseFromString(bytes(R"(0a 04 12 02 "T1")")));
  }
  SUBCASE("SyncInfo with a MachineLightSpec whose LightSpec lacks its state") {
    SyncInfo parsed;
    CHECK(!parsed.ParseFromString(bytes(R"(3a 08 0a 02 "T1" 12 02 08 00)")));
    CHECK(parsed.ParseFromString(bytes(R"(3a 0a 0a 02 "T1" 12 04 08 00 10 00)")));
  }
}

TEST_CASE("msgs: a 0.5.x beacon (no jersey number) does not parse, as on a 0.6.1 refbox") {
  const google::protobuf::LogSilencer quiet;  // the parse failures are expected
  // time {1, 0}, seq 7, team "T", peer "R-1" — everything but number (tag 8, added in 0.6.0).
  const std::string old_beacon = bytes(R"(0a 04 08 01 10 00  10 07  22 01 "T"  2a 03 "R-1")");
  llsf_msgs::BeaconSignal m;
  CHECK(!m.ParseFromString(old_beacon));
  CHECK(m.ParseFromString(old_beacon + bytes("40 05")));
  CHECK(m.number() == 5);
}

TEST_CASE("msgs: what other 2013 encoders may send decodes the same") {
  const google::protobuf::LogSilencer quiet;  // the parse failures are expected
  using namespace llsf_msgs;
  SUBCASE("packed repeated scalars are accepted (0a len 01 14 ac 02)") {
    SetPucks unpacked;
    REQUIRE(unpacked.ParseFromString(bytes("08 01 08 14 08 ac 02")));
    SetPucks packed;
    REQUIRE(packed.ParseFromString(bytes("0a 04 01 14 ac 02")));
    CHECK(MessageDifferencer::Equals(packed, unpacked));
    CHECK(packed.ids_size() == 3);
    CHECK(packed.ids(2) == 300);
    // ... but we send them unpacked, as the 2013 refbox did.
    CHECK(to_hex(packed.SerializeAsString()) == "08 01 08 14 08 ac 02");
  }
  SUBCASE("fields in any order") {
    Order in_order;
    Order reversed;
    REQUIRE(in_order.ParseFromString(bytes("08 01 10 03 18 02 20 00 30 78 38 ac 02")));
    REQUIRE(reversed.ParseFromString(bytes("38 ac 02 30 78 20 00 18 02 10 03 08 01")));
    CHECK(MessageDifferencer::Equals(in_order, reversed));
    CHECK(reversed.product() == Order::P3);
    CHECK(reversed.delivery_period_end() == 300);
  }
  SUBCASE("a non-canonical (over-long) varint: 01 as 81 00") {
    SetGameState m;
    REQUIRE(m.ParseFromString(bytes("08 82 00")));
    CHECK(m.state() == GameState::RUNNING);
  }
  SUBCASE("unknown fields are skipped and kept") {
    // An AttentionMessage with an extra string field 9 (4a 01 "z").
    AttentionMessage m;
    REQUIRE(m.ParseFromString(bytes(R"(0a 01 "x"  4a 01 "z")")));
    CHECK(m.message() == "x");
    CHECK(m.GetReflection()->GetUnknownFields(m).field_count() == 1);
    CHECK(to_hex(m.SerializeAsString()) == to_hex(bytes(R"(0a 01 "x"  4a 01 "z")")));
  }
  SUBCASE("PuckState 3 does not exist: a required state 3 is missing") {
    Puck m;
    CHECK(!m.ParseFromString(bytes("08 01 10 03")));
    CHECK(m.ParseFromString(bytes("08 01 10 04")));
    CHECK(m.state() == P1);
  }
  SUBCASE("an unknown value in a repeated enum is dropped from the field and kept as unknown") {
    Machine m;
    REQUIRE(m.ParseFromString(bytes(R"(0a 02 "M1"  18 00 18 03 18 01)")));
    REQUIRE(m.inputs_size() == 2);
    CHECK(m.inputs(0) == S0);
    CHECK(m.inputs(1) == S1);
    CHECK(m.GetReflection()->GetUnknownFields(m).field_count() == 1);
  }
  SUBCASE("0.5.x phase numbers: EXPLORATION 1 is not a 0.6.x Phase") {
    GameState m;
    CHECK(!m.ParseFromString(bytes("0a 04 08 00 10 00  18 02  20 01")));
    CHECK(m.ParseFromString(bytes("0a 04 08 00 10 00  18 02  20 14")));
    CHECK(m.phase() == GameState::EXPLORATION);
  }
  SUBCASE("floats arrive as sent, NaN and infinity included: consumers must check them") {
    // x = 0x7fc00000 (quiet NaN), y = 0x7f800000 (+inf), ori = 0x80000000 (-0.0).
    Pose2D m;
    REQUIRE(m.ParseFromString(
        bytes("0a 04 08 00 10 00  15 00 00 c0 7f  1d 00 00 80 7f  25 00 00 00 80")));
    CHECK(std::isnan(m.x()));
    CHECK(std::isinf(m.y()));
    CHECK(m.ori() == 0.0f);
    CHECK(std::signbit(m.ori()));
  }
  SUBCASE("truncated input fails") {
    const std::string full = bytes(R"(0a 02 "M1" 10 c8 01)");
    PlacePuckUnderMachine m;
    REQUIRE(m.ParseFromString(full));
    CHECK(!m.ParseFromString(full.substr(0, full.size() - 1)));  // varint cut: c8 without 01
    CHECK(!m.ParseFromString(full.substr(0, 3)));                // string cut
  }
}

}  // namespace
