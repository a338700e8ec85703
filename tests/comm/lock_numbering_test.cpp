// SPDX-License-Identifier: MIT
// The lock messages under the 2013 numbering (radio `lock_messages: 2013`): on the wire as
// (2000, 1337) and (2000, 1338), decodable by a peer that knows them as the 2013 agent declared
// them (package llsf_msgs), and back; the other agents' messages keep (2100, type).
#include <doctest/doctest.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <llsf_agent_msgs/LockMessage.pb.h>

#include <memory>
#include <string>
#include <vector>

#include "comm/loopback.h"
#include "llsf/comm/hub_config.h"
#include "llsf/comm/registry.h"
#include "llsf/comm/stream.h"
#include "llsf/core/error.h"

using namespace llsf::comm;
namespace pb = google::protobuf;

namespace {

/// A 2013 peer's view of the lock messages: package llsf_msgs, LockMessage {required LockType
/// type = 1; required string agent = 2; required string resource = 3} and LockMasterAnnounce
/// {required string agent = 1}, built at run time from their descriptors (fawkes-conventions
/// §3.3), registered under (2000, 1337) and (2000, 1338). Nothing of llsfsim's own .proto is used.
struct Peer2013 {
  pb::DescriptorPool pool;
  pb::DynamicMessageFactory factory{&pool};
  MessageRegistry registry;
  const pb::Descriptor* lock = nullptr;
  const pb::Descriptor* announce = nullptr;

  Peer2013() {
    pb::FileDescriptorProto file;
    file.set_name("LockMessage2013.proto");
    file.set_package("llsf_msgs");
    file.set_syntax("proto2");
    const auto field = [](pb::DescriptorProto* m, const char* name, int number,
                          pb::FieldDescriptorProto::Type type) {
      pb::FieldDescriptorProto* f = m->add_field();
      f->set_name(name);
      f->set_number(number);
      f->set_label(pb::FieldDescriptorProto::LABEL_REQUIRED);
      f->set_type(type);
      return f;
    };
    pb::DescriptorProto* m = file.add_message_type();
    m->set_name("LockMessage");
    pb::EnumDescriptorProto* types = m->add_enum_type();
    types->set_name("LockType");
    int value = 1;
    for (const char* name : {"GET", "REFUSE", "ACCEPT", "RELEASE", "RELEASE_RVCD"}) {
      pb::EnumValueDescriptorProto* v = types->add_value();
      v->set_name(name);
      v->set_number(value++);
    }
    field(m, "type", 1, pb::FieldDescriptorProto::TYPE_ENUM)
        ->set_type_name(".llsf_msgs.LockMessage.LockType");
    field(m, "agent", 2, pb::FieldDescriptorProto::TYPE_STRING);
    field(m, "resource", 3, pb::FieldDescriptorProto::TYPE_STRING);
    pb::DescriptorProto* a = file.add_message_type();
    a->set_name("LockMasterAnnounce");
    field(a, "agent", 1, pb::FieldDescriptorProto::TYPE_STRING);
    const pb::FileDescriptor* fd = pool.BuildFile(file);
    REQUIRE(fd != nullptr);
    lock = fd->FindMessageTypeByName("LockMessage");
    announce = fd->FindMessageTypeByName("LockMasterAnnounce");
    registry.add(MessageKey{2000, 1337}, *factory.GetPrototype(lock));
    registry.add(MessageKey{2000, 1338}, *factory.GetPrototype(announce));
  }

  std::unique_ptr<pb::Message> make_lock(const std::string& type, const std::string& agent,
                                         const std::string& resource) {
    std::unique_ptr<pb::Message> m(factory.GetPrototype(lock)->New());
    const pb::Reflection* r = m->GetReflection();
    r->SetEnum(m.get(), lock->FindFieldByName("type"),
               lock->FindEnumTypeByName("LockType")->FindValueByName(type));
    r->SetString(m.get(), lock->FindFieldByName("agent"), agent);
    r->SetString(m.get(), lock->FindFieldByName("resource"), resource);
    return m;
  }
};

std::string field(const pb::Message& m, const char* name) {
  const pb::FieldDescriptor* f = m.GetDescriptor()->FindFieldByName(name);
  REQUIRE(f != nullptr);
  if (f->type() == pb::FieldDescriptor::TYPE_ENUM) {
    return m.GetReflection()->GetEnum(m, f)->name();
  }
  return m.GetReflection()->GetString(m, f);
}

}  // namespace

TEST_CASE("lock numbering 2013: the lock messages are (2000, 1337) and (2000, 1338) on the wire") {
  MessageRegistry ours;
  add_agent_messages(ours, LockNumbering::k2013);
  MessageRegistry def;
  add_agent_messages(def);

  // The header: component 2000 = 0x07d0, type 1337 = 0x0539 and 1338 = 0x053a, big-endian.
  const std::vector<std::uint8_t> f = ours.encode(test::lock(3));
  REQUIRE(f.size() > kHeaderSize);
  CHECK(std::vector<std::uint8_t>(f.begin(), f.begin() + 4) ==
        std::vector<std::uint8_t>{0x07, 0xd0, 0x05, 0x39});
  llsf_agent_msgs::LockMasterAnnounce a;
  a.set_agent("R2");
  const std::vector<std::uint8_t> g = ours.encode(a);
  CHECK(std::vector<std::uint8_t>(g.begin(), g.begin() + 4) ==
        std::vector<std::uint8_t>{0x07, 0xd0, 0x05, 0x3a});
  // The payload is the same bytes as under llsfsim's numbering; only the pair differs.
  const std::vector<std::uint8_t> d = def.encode(test::lock(3));
  CHECK(std::vector<std::uint8_t>(f.begin() + 4, f.end()) ==
        std::vector<std::uint8_t>(d.begin() + 4, d.end()));
  CHECK(std::vector<std::uint8_t>(d.begin(), d.begin() + 4) ==
        std::vector<std::uint8_t>{0x08, 0x34, 0x00, 0x01});

  // The others keep (2100, type); the dense indices and names are the same in both registries.
  CHECK(ours.key_of(llsf_agent_msgs::LockStatus::default_instance()) == MessageKey{2100, 3});
  REQUIRE(ours.size() == def.size());
  for (int i = 0; i < ours.size(); ++i) {
    CAPTURE(i);
    CHECK(ours.name_at(i) == def.name_at(i));
    CHECK(is_agent_message(ours, i));
    CHECK((ours.key_at(i) == def.key_at(i)) == (i >= 2));
  }
  CHECK(ours.key_at(0) == MessageKey{kRefboxComponentId, k2013LockMessageType});
  CHECK(ours.key_at(1) == MessageKey{kRefboxComponentId, k2013LockMasterAnnounceType});

  // Each numbering refuses the other's frames as unknown types: the switch is all or nothing.
  CHECK(def.decode_datagram(f).error == FrameError::kUnknownType);
  CHECK(ours.decode_datagram(d).error == FrameError::kUnknownType);
}

TEST_CASE("lock numbering 2013: a peer that knows llsf_msgs.LockMessage decodes them, and back") {
  MessageRegistry ours;
  add_agent_messages(ours, LockNumbering::k2013);
  Peer2013 peer;

  // Ours to the peer, as one datagram and through the stream decoder.
  const std::vector<std::uint8_t> f = ours.encode(test::lock(5));
  const MessageRegistry::Decoded at_peer = peer.registry.decode_datagram(f);
  REQUIRE(at_peer.error == FrameError::kNone);
  CHECK(at_peer.message->GetTypeName() == "llsf_msgs.LockMessage");
  CHECK(field(*at_peer.message, "type") == "GET");
  CHECK(field(*at_peer.message, "agent") == "R1");
  CHECK(field(*at_peer.message, "resource") == "M5");
  llsf_agent_msgs::LockMasterAnnounce a;
  a.set_agent("R3");
  const MessageRegistry::Decoded ann = peer.registry.decode_datagram(ours.encode(a));
  REQUIRE(ann.error == FrameError::kNone);
  CHECK(ann.message->GetTypeName() == "llsf_msgs.LockMasterAnnounce");
  CHECK(field(*ann.message, "agent") == "R3");
  StreamDecoder stream;
  stream.feed(f);
  stream.feed(ours.encode(a));
  for (const char* type : {"llsf_msgs.LockMessage", "llsf_msgs.LockMasterAnnounce"}) {
    const StreamDecoder::Next next = stream.next();
    REQUIRE(next.status == StreamDecoder::Next::Status::kFrame);
    const MessageRegistry::Decoded m = peer.registry.decode(next.frame);
    REQUIRE(m.error == FrameError::kNone);
    CHECK(m.message->GetTypeName() == type);
  }

  // The peer's to ours: every lock type.
  for (const char* type : {"GET", "REFUSE", "ACCEPT", "RELEASE", "RELEASE_RVCD"}) {
    CAPTURE(type);
    const std::unique_ptr<pb::Message> m = peer.make_lock(type, "R2", "D1");
    const std::vector<std::uint8_t> frame = peer.registry.encode(*m);
    CHECK(frame[0] == 0x07);
    CHECK(frame[3] == 0x39);
    const MessageRegistry::Decoded at_us = ours.decode_datagram(frame);
    REQUIRE(at_us.error == FrameError::kNone);
    const auto& lock = dynamic_cast<const llsf_agent_msgs::LockMessage&>(*at_us.message);
    CHECK(llsf_agent_msgs::LockMessage::LockType_Name(lock.type()) == type);
    CHECK(lock.agent() == "R2");
    CHECK(lock.resource() == "D1");
  }
}

TEST_CASE("radio lock_messages: llsfsim (default) or 2013; anything else names file:line") {
  using llsf::core::ConfigNode;
  CHECK(load_hub_config(ConfigNode::parse("{}", "r.yaml")).lock_messages ==
        LockNumbering::kLlsfsim);
  CHECK(load_hub_config(ConfigNode::parse("lock_messages: 2013\n", "r.yaml")).lock_messages ==
        LockNumbering::k2013);
  CHECK(load_hub_config(ConfigNode::parse("lock_messages: llsfsim\n", "r.yaml")).lock_messages ==
        LockNumbering::kLlsfsim);
  std::string error;
  try {
    load_hub_config(ConfigNode::parse("delay: {fixed_ms: 1}\nlock_messages: 2014\n", "r.yaml"));
  } catch (const llsf::core::ConfigError& e) {
    error = e.what();
  }
  CHECK(error ==
        "r.yaml:2:16: lock_messages: unknown lock message numbering '2014' (expected llsfsim: "
        "component 2100, or 2013: component 2000, types 1337 and 1338)");
}
