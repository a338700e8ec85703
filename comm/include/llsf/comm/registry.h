// SPDX-License-Identifier: MIT
// MessageRegistry: which protobuf message type a (component id, message type) pair stands for,
// and the encoding/decoding of whole frames with it.
//
// The registry is generic: the refbox messages (llsf_msgs, component 2000) are registered by
// whoever wires the game, the agents' own messages (llsf_agent_msgs, component 2100) by
// add_agent_messages(). Messages declare their pair in a nested `enum CompType { COMP_ID = ..;
// MSG_TYPE = ..; }` (llsf2013-rules.md §9.3), which add<T>() reads.
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "llsf/comm/frame.h"

namespace llsf::comm {

/// Component id of the agents' own messages (locks, world-model sync, auctions).
inline constexpr int kAgentComponentId = 2100;
/// Component id of the 2013 refbox messages (llsf_msgs).
inline constexpr int kRefboxComponentId = 2000;

/// Maps (component id, message type) pairs to protobuf prototypes and back. Each registered
/// type also gets a dense index 0..size()-1 (in registration order) for counter tables.
/// Copyable (a copy registers the same prototypes); not thread-safe: validate() uses scratch
/// messages.
class MessageRegistry {
 public:
  MessageRegistry() = default;
  MessageRegistry(const MessageRegistry& other);
  MessageRegistry& operator=(const MessageRegistry& other);
  MessageRegistry(MessageRegistry&&) noexcept = default;
  MessageRegistry& operator=(MessageRegistry&&) noexcept = default;
  ~MessageRegistry() = default;

  /// Registers T under (T::COMP_ID, T::MSG_TYPE).
  template <class T>
  void add() {
    add(MessageKey{static_cast<int>(T::COMP_ID), static_cast<int>(T::MSG_TYPE)},
        T::default_instance());
  }
  /// Registers `prototype`'s type under `key`; the prototype must outlive the registry (the
  /// generated default instances do). Registering the same type under the same key again is a
  /// no-op; a key or type that is already taken by something else is a programmer error.
  void add(MessageKey key, const google::protobuf::Message& prototype);

  /// Number of registered types.
  int size() const { return static_cast<int>(entries_.size()); }
  /// Dense index of `key`, if registered.
  std::optional<int> index_of(MessageKey key) const;
  /// Dense index of `message`'s type, if registered.
  std::optional<int> index_of(const google::protobuf::Message& message) const;
  /// The key of the type with dense index `index`.
  MessageKey key_at(int index) const { return entries_.at(static_cast<std::size_t>(index)).key; }
  /// The full protobuf name of the type with dense index `index`, e.g. "llsf_msgs.GameState".
  const std::string& name_at(int index) const;
  /// The key under which `message`'s type is registered, if it is.
  std::optional<MessageKey> key_of(const google::protobuf::Message& message) const;
  /// The prototype registered under `key`, or nullptr.
  const google::protobuf::Message* prototype(MessageKey key) const;

  /// Encodes `message` as one frame (header + payload) into `out` (resized; its capacity is
  /// reused). Returns false, leaving `out` empty, if the type is not registered or the message
  /// lacks required fields.
  bool encode(const google::protobuf::Message& message, std::vector<std::uint8_t>& out) const;
  /// encode() into a new vector; throws std::invalid_argument if it cannot be encoded.
  std::vector<std::uint8_t> encode(const google::protobuf::Message& message) const;

  /// The result of decoding one frame.
  struct Decoded {
    FrameError error = FrameError::kNone;
    MessageKey key;                                      ///< set once the header was read
    std::unique_ptr<google::protobuf::Message> message;  ///< set iff error == kNone
  };
  /// Decodes a frame whose framing was already checked (check_datagram, StreamDecoder).
  Decoded decode(const FrameView& frame) const;
  /// Checks and decodes one UDP datagram.
  Decoded decode_datagram(std::span<const std::uint8_t> datagram,
                          int max_frame_bytes = kMaxDatagramSize) const;
  /// Checks that `frame`'s type is registered and its payload parses, without keeping the
  /// message; returns the dense index through `index` on success. Reuses one scratch message
  /// per type, so it does not allocate for small messages after the first call; not safe to call
  /// concurrently.
  FrameError validate(const FrameView& frame, int* index = nullptr) const;

 private:
  struct Entry {
    MessageKey key;
    const google::protobuf::Message* prototype;
    std::string name;
    mutable std::unique_ptr<google::protobuf::Message> scratch;  ///< for validate(), lazily
  };
  std::vector<Entry> entries_;
  std::map<MessageKey, int> by_key_;
  std::map<const google::protobuf::Descriptor*, int> by_descriptor_;
};

/// Message types of the 2013 Carologistics agent's LockMessage and LockMasterAnnounce, which it
/// sent inside the refbox's component 2000 (package llsf_msgs).
inline constexpr int k2013LockMessageType = 1337;
inline constexpr int k2013LockMasterAnnounceType = 1338;

/// Where the lock messages go on the wire (docs/comm.md, "Message types and component ids").
enum class LockNumbering {
  kLlsfsim,  ///< LockMessage (2100, 1), LockMasterAnnounce (2100, 2): the default
  k2013,     ///< LockMessage (2000, 1337), LockMasterAnnounce (2000, 1338): the 2013 agent's
};
/// "llsfsim", "2013" (the values of the radio's `lock_messages` key).
const char* lock_numbering_name(LockNumbering n);

/// Registers the agents' own messages (llsf_agent_msgs: LockMessage, LockMasterAnnounce,
/// LockStatus, Worldmodel, WorldmodelChange, AuctionCall, AuctionBid, AuctionAward, AuctionAck,
/// AuctionStatus), the two lock messages under `locks`' numbering, the others at (2100, type).
/// The registration order (the dense indices) is the same for both numberings.
void add_agent_messages(MessageRegistry& registry, LockNumbering locks = LockNumbering::kLlsfsim);

/// True if the type with dense index `index` is one of the agents' messages (package
/// llsf_agent_msgs, or read from an agent's own .proto files: comm::ProtoLibrary), whatever its
/// component id: with LockNumbering::k2013 two of them share the
/// refbox's component 2000, but they are not the refbox's business.
bool is_agent_message(const MessageRegistry& registry, int index);

}  // namespace llsf::comm
