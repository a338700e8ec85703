// SPDX-License-Identifier: MIT
// The 2013 frame codec and the message registry: round trips, and every malformed case refused.
#include <doctest/doctest.h>
#include <llsf_agent_msgs/Auction.pb.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <cstdint>
#include <vector>

#include "llsf/comm/frame.h"
#include "llsf/comm/hub.h"
#include "llsf/comm/registry.h"
#include "llsf/core/assert.h"

using namespace llsf::comm;
using Bytes = std::vector<std::uint8_t>;

namespace {

MessageRegistry agent_registry() {
  MessageRegistry r;
  add_agent_messages(r);
  return r;
}

llsf_agent_msgs::LockMessage lock_msg(const std::string& resource) {
  llsf_agent_msgs::LockMessage m;
  m.set_type(llsf_agent_msgs::LockMessage::GET);
  m.set_agent("R1");
  m.set_resource(resource);
  return m;
}

Bytes frame_bytes(int comp, int type, const Bytes& payload) {
  Bytes out(kHeaderSize);
  write_header(std::span<std::uint8_t, kHeaderSize>(out.data(), kHeaderSize),
               MessageKey{comp, type}, static_cast<std::int64_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

}  // namespace

TEST_CASE("header is big-endian component id, message type, payload size") {
  Bytes h(8);
  write_header(std::span<std::uint8_t, 8>(h.data(), 8), MessageKey{2000, 0x1234}, 0x01020304);
  CHECK(h == Bytes{0x07, 0xd0, 0x12, 0x34, 0x01, 0x02, 0x03, 0x04});
  const auto r = read_header(h);
  REQUIRE(r);
  CHECK(r->key == MessageKey{2000, 0x1234});
  CHECK(r->payload_size == 0x01020304);
  // The extremes of each field survive.
  write_header(std::span<std::uint8_t, 8>(h.data(), 8), MessageKey{65535, 65535}, 0xffffffffLL);
  CHECK(read_header(h)->key == MessageKey{65535, 65535});
  CHECK(read_header(h)->payload_size == 0xffffffffLL);
  CHECK_FALSE(read_header(std::span<const std::uint8_t>(h.data(), 7)));
  CHECK_THROWS_AS(write_header(std::span<std::uint8_t, 8>(h.data(), 8), MessageKey{65536, 1}, 0),
                  llsf::core::AssertionError);
}

TEST_CASE("registry reads COMP_ID/MSG_TYPE and gives dense indices") {
  const MessageRegistry r = agent_registry();
  CHECK(r.size() == 10);
  CHECK(r.key_of(llsf_agent_msgs::LockMessage()) == MessageKey{kAgentComponentId, 1});
  CHECK(r.key_of(llsf_agent_msgs::LockMasterAnnounce()) == MessageKey{2100, 2});
  CHECK(r.key_of(llsf_agent_msgs::Worldmodel()) == MessageKey{2100, 10});
  CHECK(r.key_of(llsf_agent_msgs::AuctionAward()) == MessageKey{2100, 22});
  CHECK(r.index_of(MessageKey{2100, 1}) == 0);
  CHECK(r.name_at(0) == "llsf_agent_msgs.LockMessage");
  CHECK_FALSE(r.index_of(MessageKey{2100, 99}));
  CHECK(r.prototype(MessageKey{2100, 11}) ==
        &llsf_agent_msgs::WorldmodelChange::default_instance());

  MessageRegistry copy = r;
  copy.add<llsf_agent_msgs::LockMessage>();  // same type, same key: no-op
  CHECK(copy.size() == 10);
  // Another type under a taken key, or a taken type under another key, is a bug.
  CHECK_THROWS_AS(copy.add(MessageKey{2100, 1}, llsf_agent_msgs::AuctionBid::default_instance()),
                  llsf::core::AssertionError);
  CHECK_THROWS_AS(copy.add(MessageKey{2100, 77}, llsf_agent_msgs::AuctionBid::default_instance()),
                  llsf::core::AssertionError);
  copy.add(MessageKey{3000, 5}, llsf_agent_msgs::Incoming::default_instance());
  CHECK(copy.index_of(MessageKey{3000, 5}) == 10);
}

TEST_CASE("encode/decode round trip") {
  const MessageRegistry r = agent_registry();
  SUBCASE("LockMessage") {
    const Bytes f = r.encode(lock_msg("M3"));
    const auto h = read_header(f);
    REQUIRE(h);
    CHECK(h->key == MessageKey{2100, 1});
    CHECK(h->payload_size == static_cast<std::int64_t>(f.size()) - 8);
    const auto d = r.decode_datagram(f);
    REQUIRE(d.error == FrameError::kNone);
    CHECK(d.key == MessageKey{2100, 1});
    const auto& m = dynamic_cast<const llsf_agent_msgs::LockMessage&>(*d.message);
    CHECK(m.type() == llsf_agent_msgs::LockMessage::GET);
    CHECK(m.agent() == "R1");
    CHECK(m.resource() == "M3");
  }
  SUBCASE("Worldmodel with nested and repeated fields") {
    llsf_agent_msgs::Worldmodel wm;
    wm.set_sender("R2");
    wm.set_seq(42);
    auto* m = wm.add_machines();
    m->set_name("M7");
    m->add_loaded_with(llsf_agent_msgs::S1);
    m->add_loaded_with(llsf_agent_msgs::S0);
    auto* in = m->add_incoming();
    in->set_action("BRING_S2");
    in->set_agent("R3");
    m->set_prod_finished_time(123.5);
    auto* o = wm.add_orders();
    o->set_id(3);
    o->set_in_delivery(1);
    const auto d = r.decode_datagram(r.encode(wm));
    REQUIRE(d.error == FrameError::kNone);
    CHECK(d.message->SerializeAsString() == wm.SerializeAsString());
  }
  SUBCASE("empty payload") {
    llsf_agent_msgs::LockStatus ls;
    ls.set_master("R1");
    ls.clear_master();
    Bytes out;
    CHECK_FALSE(r.encode(ls, out));  // required field missing
    CHECK(out.empty());
    CHECK_THROWS_AS(r.encode(ls), std::invalid_argument);
  }
  SUBCASE("unregistered type is not encoded") {
    Bytes out{1, 2, 3};
    CHECK_FALSE(r.encode(llsf_agent_msgs::Incoming(), out));
    CHECK(out.empty());
  }
}

TEST_CASE("every malformed datagram is refused with its reason") {
  const MessageRegistry r = agent_registry();
  const Bytes good = r.encode(lock_msg("M1"));
  REQUIRE(r.decode_datagram(good).error == FrameError::kNone);

  SUBCASE("short header") {
    for (std::size_t n = 0; n < 8; ++n) {
      CHECK(r.decode_datagram(std::span(good.data(), n)).error == FrameError::kShortHeader);
    }
  }
  SUBCASE("size mismatch: truncated payload, trailing bytes") {
    CHECK(r.decode_datagram(std::span(good.data(), good.size() - 1)).error ==
          FrameError::kSizeMismatch);
    CHECK(r.decode_datagram(std::span(good.data(), 8)).error == FrameError::kSizeMismatch);
    Bytes longer = good;
    longer.push_back(0);
    CHECK(r.decode_datagram(longer).error == FrameError::kSizeMismatch);
  }
  SUBCASE("oversized: datagram above 1024 bytes, or a header announcing more") {
    llsf_agent_msgs::LockMessage big = lock_msg(std::string(1100, 'x'));
    const Bytes f = r.encode(big);
    CHECK(f.size() > 1024);
    CHECK(r.decode_datagram(f).error == FrameError::kOversized);
    CHECK(r.decode_datagram(f, 4096).error == FrameError::kNone);
    // Exactly 1024 bytes is fine, 1025 is not.
    const Bytes at_limit = frame_bytes(2100, 1, Bytes(1016, 0));
    CHECK(r.decode_datagram(at_limit).error != FrameError::kOversized);
    const Bytes over = frame_bytes(2100, 1, Bytes(1017, 0));
    CHECK(r.decode_datagram(over).error == FrameError::kOversized);
    // A short datagram whose header claims 4 GB.
    Bytes liar = good;
    liar[4] = liar[5] = liar[6] = liar[7] = 0xff;
    CHECK(r.decode_datagram(liar).error == FrameError::kOversized);
  }
  SUBCASE("unknown type") {
    Bytes f = good;
    f[3] = 99;
    CHECK(r.decode_datagram(f).error == FrameError::kUnknownType);
    CHECK(r.decode_datagram(f).key == MessageKey{2100, 99});
    f = good;
    f[0] = 0x07;  // component 2000 + 0x68..: not ours
    CHECK(r.decode_datagram(f).error == FrameError::kUnknownType);
  }
  SUBCASE("garbage payload") {
    CHECK(r.decode_datagram(frame_bytes(2100, 1, Bytes{0xff, 0xff, 0xff})).error ==
          FrameError::kBadPayload);
    // Wire-valid protobuf that lacks the required fields.
    CHECK(r.decode_datagram(frame_bytes(2100, 1, Bytes{})).error == FrameError::kBadPayload);
    CHECK(r.decode_datagram(frame_bytes(2100, 1, Bytes{0x08, 0x01})).error ==
          FrameError::kBadPayload);
    // validate() agrees with decode().
    const Bytes bad = frame_bytes(2100, 1, Bytes{0xff, 0xff});
    const DatagramCheck c = check_datagram(bad);  // views into `bad`
    REQUIRE(c.error == FrameError::kNone);
    CHECK(r.validate(c.frame) == FrameError::kBadPayload);
  }
}

TEST_CASE("stream decoder: split anywhere, many frames per read, oversized breaks") {
  const MessageRegistry r = agent_registry();
  Bytes stream;
  std::vector<std::string> resources;
  for (int i = 0; i < 5; ++i) {
    std::string res = "M";
    res += std::to_string(i + 1);
    res.append(static_cast<std::size_t>(i * 7), 'z');
    resources.push_back(res);
    const Bytes f = r.encode(lock_msg(resources.back()));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  const auto drain = [&](StreamDecoder& d, std::vector<std::string>& got) {
    for (;;) {
      const auto n = d.next();
      if (n.status != StreamDecoder::Next::Status::kFrame) {
        CHECK(n.status == StreamDecoder::Next::Status::kNeedMore);
        return;
      }
      const auto dec = r.decode(n.frame);
      REQUIRE(dec.error == FrameError::kNone);
      got.push_back(dynamic_cast<const llsf_agent_msgs::LockMessage&>(*dec.message).resource());
    }
  };
  SUBCASE("one byte at a time") {
    StreamDecoder d;
    std::vector<std::string> got;
    for (std::size_t i = 0; i < stream.size(); ++i) {
      d.feed(std::span(stream.data() + i, 1));
      drain(d, got);
    }
    CHECK(got == resources);
    CHECK(d.buffered() == 0);
  }
  SUBCASE("everything at once") {
    StreamDecoder d;
    std::vector<std::string> got;
    d.feed(stream);
    drain(d, got);
    CHECK(got == resources);
  }
  SUBCASE("every split point of chunks of 3, 5 and 13 bytes") {
    for (const std::size_t chunk : {3u, 5u, 13u}) {
      StreamDecoder d;
      std::vector<std::string> got;
      for (std::size_t i = 0; i < stream.size(); i += chunk) {
        d.feed(std::span(stream.data() + i, std::min(chunk, stream.size() - i)));
        drain(d, got);
      }
      CHECK(got == resources);
    }
  }
  SUBCASE("oversized header") {
    StreamDecoder d(100);
    const Bytes big = frame_bytes(2100, 1, Bytes(101, 0));
    d.feed(std::span(big.data(), 8));
    CHECK(d.next().status == StreamDecoder::Next::Status::kOversized);
    CHECK(d.broken());
    d.feed(stream);  // ignored: the stream cannot be resynchronised
    CHECK(d.next().status == StreamDecoder::Next::Status::kOversized);
  }
}

TEST_CASE("frame_error_name") {
  CHECK(frame_error_name(FrameError::kShortHeader) == "short_header");
  CHECK(frame_error_name(FrameError::kBadPayload) == "bad_payload");
}

#if defined(LLSF_HAVE_MSGS) && __has_include(<llsf_msgs/BeaconSignal.pb.h>)
#include <llsf_msgs/BeaconSignal.pb.h>

TEST_CASE("a real refbox message (llsf_msgs.BeaconSignal, 2000/1) round-trips") {
  MessageRegistry r = agent_registry();
  r.add<llsf_msgs::BeaconSignal>();
  llsf_msgs::BeaconSignal b;
  b.mutable_time()->set_sec(1);
  b.mutable_time()->set_nsec(2);
  b.set_seq(7);
  b.set_team_name("Carologistics");
  b.set_peer_name("R1");
  b.set_number(1);
  const Bytes f = r.encode(b);
  CHECK(read_header(f)->key == MessageKey{2000, 1});
  const auto d = r.decode_datagram(f);
  REQUIRE(d.error == FrameError::kNone);
  CHECK(d.message->SerializeAsString() == b.SerializeAsString());

  // Through the hub, next to the agents' messages.
  Hub hub(HubConfig{}, r, llsf::core::Rng(1));
  const PeerId robot = hub.add_peer("robot1");
  const PeerId refbox = hub.add_peer("refbox", "*");
  CHECK(hub.broadcast(robot, b, SimTime::from_ms(0)) == FrameError::kNone);
  CHECK(hub.broadcast(robot, lock_msg("M2"), SimTime::from_ms(0)) == FrameError::kNone);
  hub.step(SimTime::from_ms(2));
  REQUIRE(hub.received(refbox).size() == 2);
  const auto got = hub.decode(hub.received(refbox)[0]);
  CHECK(dynamic_cast<const llsf_msgs::BeaconSignal&>(*got).team_name() == "Carologistics");
  CHECK(r.key_at(hub.received(refbox)[1].type_index) == MessageKey{2100, 1});
}
#endif
