// SPDX-License-Identifier: MIT
// MessageRegistry: (component id, message type) <-> protobuf type, frame encoding and decoding.
#include "llsf/comm/registry.h"

#include <google/protobuf/descriptor.h>

#include <llsf_agent_msgs/Auction.pb.h>
#include <llsf_agent_msgs/LockMessage.pb.h>
#include <llsf_agent_msgs/Worldmodel.pb.h>

#include <google/protobuf/stubs/logging.h>

#include <stdexcept>

#include "llsf/core/assert.h"

namespace llsf::comm {

namespace {
// Generated code built without NDEBUG logs every string field with invalid UTF-8 when parsing
// and serialising (proto2 only logs, it does not refuse). Frames are bytes to us: a bad one is an
// expected outcome, counted, not logged. (LogSilencer takes a mutex, so only where it matters.)
#ifndef NDEBUG
#define LLSF_COMM_QUIET_PROTOBUF const google::protobuf::LogSilencer quiet_protobuf
#else
#define LLSF_COMM_QUIET_PROTOBUF static_cast<void>(0)
#endif

/// Parses a payload and checks required fields (ParseFromArray would do both, but logs every
/// missing field).
bool parse(google::protobuf::Message& m, std::span<const std::uint8_t> payload) {
  LLSF_COMM_QUIET_PROTOBUF;
  return m.ParsePartialFromArray(payload.data(), static_cast<int>(payload.size())) &&
         m.IsInitialized();
}
}  // namespace

MessageRegistry::MessageRegistry(const MessageRegistry& other) { *this = other; }

MessageRegistry& MessageRegistry::operator=(const MessageRegistry& other) {
  if (this == &other) return *this;
  entries_.clear();
  entries_.reserve(other.entries_.size());
  for (const Entry& e : other.entries_) entries_.push_back(Entry{e.key, e.prototype, e.name, {}});
  by_key_ = other.by_key_;
  by_descriptor_ = other.by_descriptor_;
  return *this;
}

void MessageRegistry::add(MessageKey key, const google::protobuf::Message& prototype) {
  LLSF_DEMAND(key.component_id >= 0 && key.component_id <= 0xffff);
  LLSF_DEMAND(key.msg_type >= 0 && key.msg_type <= 0xffff);
  const google::protobuf::Descriptor* d = prototype.GetDescriptor();
  const auto k = by_key_.find(key);
  const auto t = by_descriptor_.find(d);
  if (k != by_key_.end() && t != by_descriptor_.end() && k->second == t->second) return;
  LLSF_DEMAND_MSG(k == by_key_.end(), "message key (" + std::to_string(key.component_id) + ", " +
                                          std::to_string(key.msg_type) + ") already registered");
  LLSF_DEMAND_MSG(t == by_descriptor_.end(),
                  "message type " + d->full_name() + " already registered under another key");
  const int index = size();
  entries_.push_back(Entry{key, &prototype, d->full_name(), {}});
  by_key_.emplace(key, index);
  by_descriptor_.emplace(d, index);
}

std::optional<int> MessageRegistry::index_of(MessageKey key) const {
  const auto it = by_key_.find(key);
  if (it == by_key_.end()) return std::nullopt;
  return it->second;
}

std::optional<int> MessageRegistry::index_of(const google::protobuf::Message& message) const {
  const auto it = by_descriptor_.find(message.GetDescriptor());
  if (it == by_descriptor_.end()) return std::nullopt;
  return it->second;
}

const std::string& MessageRegistry::name_at(int index) const {
  return entries_.at(static_cast<std::size_t>(index)).name;
}

std::optional<MessageKey> MessageRegistry::key_of(const google::protobuf::Message& message) const {
  const auto i = index_of(message);
  if (!i) return std::nullopt;
  return entries_[static_cast<std::size_t>(*i)].key;
}

const google::protobuf::Message* MessageRegistry::prototype(MessageKey key) const {
  const auto i = index_of(key);
  return i ? entries_[static_cast<std::size_t>(*i)].prototype : nullptr;
}

bool MessageRegistry::encode(const google::protobuf::Message& message,
                             std::vector<std::uint8_t>& out) const {
  out.clear();
  const auto key = key_of(message);
  if (!key || !message.IsInitialized()) return false;
  const auto payload = static_cast<std::int64_t>(message.ByteSizeLong());
  if (payload > 0xffffffffLL) return false;
  out.resize(static_cast<std::size_t>(kHeaderSize + payload));
  write_header(std::span<std::uint8_t, kHeaderSize>(out.data(), kHeaderSize), *key, payload);
  // ByteSizeLong() cached the sizes; serialising with them does not allocate.
  LLSF_COMM_QUIET_PROTOBUF;
  message.SerializeWithCachedSizesToArray(out.data() + kHeaderSize);
  return true;
}

std::vector<std::uint8_t> MessageRegistry::encode(const google::protobuf::Message& message) const {
  std::vector<std::uint8_t> out;
  if (!encode(message, out)) {
    throw std::invalid_argument("cannot encode " + message.GetTypeName() +
                                ": type not registered or required fields missing");
  }
  return out;
}

MessageRegistry::Decoded MessageRegistry::decode(const FrameView& frame) const {
  Decoded d;
  d.key = frame.header.key;
  const auto i = index_of(frame.header.key);
  if (!i) {
    d.error = FrameError::kUnknownType;
    return d;
  }
  std::unique_ptr<google::protobuf::Message> m(
      entries_[static_cast<std::size_t>(*i)].prototype->New());
  if (!parse(*m, frame.payload)) {
    d.error = FrameError::kBadPayload;
    return d;
  }
  d.message = std::move(m);
  return d;
}

MessageRegistry::Decoded MessageRegistry::decode_datagram(std::span<const std::uint8_t> datagram,
                                                          int max_frame_bytes) const {
  const DatagramCheck c = check_datagram(datagram, max_frame_bytes);
  if (c.error != FrameError::kNone) {
    Decoded d;
    d.error = c.error;
    if (const auto h = read_header(datagram)) d.key = h->key;
    return d;
  }
  return decode(c.frame);
}

FrameError MessageRegistry::validate(const FrameView& frame, int* index) const {
  const auto i = index_of(frame.header.key);
  if (!i) return FrameError::kUnknownType;
  const Entry& e = entries_[static_cast<std::size_t>(*i)];
  if (!e.scratch) e.scratch.reset(e.prototype->New());
  if (!parse(*e.scratch, frame.payload)) {
    return FrameError::kBadPayload;
  }
  if (index) *index = *i;
  return FrameError::kNone;
}

const char* lock_numbering_name(LockNumbering n) {
  return n == LockNumbering::k2013 ? "2013" : "llsfsim";
}

void add_agent_messages(MessageRegistry& registry, LockNumbering locks) {
  if (locks == LockNumbering::k2013) {
    // The 2013 agent's own .proto declared these in package llsf_msgs with the same fields; the
    // package is not on the wire, the pair and the field numbers are.
    registry.add(MessageKey{kRefboxComponentId, k2013LockMessageType},
                 llsf_agent_msgs::LockMessage::default_instance());
    registry.add(MessageKey{kRefboxComponentId, k2013LockMasterAnnounceType},
                 llsf_agent_msgs::LockMasterAnnounce::default_instance());
  } else {
    registry.add<llsf_agent_msgs::LockMessage>();
    registry.add<llsf_agent_msgs::LockMasterAnnounce>();
  }
  registry.add<llsf_agent_msgs::LockStatus>();
  registry.add<llsf_agent_msgs::Worldmodel>();
  registry.add<llsf_agent_msgs::WorldmodelChange>();
  registry.add<llsf_agent_msgs::AuctionCall>();
  registry.add<llsf_agent_msgs::AuctionBid>();
  registry.add<llsf_agent_msgs::AuctionAward>();
  registry.add<llsf_agent_msgs::AuctionAck>();
  registry.add<llsf_agent_msgs::AuctionStatus>();
}

bool is_agent_message(const MessageRegistry& registry, int index) {
  const google::protobuf::Message* p = registry.prototype(registry.key_at(index));
  // Also a type read from an agent's own .proto files (comm::ProtoLibrary): not compiled into
  // llsfsim, so not the refbox's, even in its package llsf_msgs (the 2013 agent's LockMessage).
  return p != nullptr &&
         (p->GetDescriptor()->file()->package() == "llsf_agent_msgs" ||
          p->GetDescriptor()->file()->pool() != google::protobuf::DescriptorPool::generated_pool());
}

}  // namespace llsf::comm
