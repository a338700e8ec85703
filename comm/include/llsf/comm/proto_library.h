// SPDX-License-Identifier: MIT
// ProtoLibrary: message types read from .proto files at run time -- a Fawkes-style agent's own
// messages (its msgs/ directory, as Fawkes' clips-protobuf proto-dirs), docs/fawkes.md.
#pragma once

#include <google/protobuf/message.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "llsf/comm/frame.h"

namespace llsf::comm {

class MessageRegistry;

/// The message types of the .proto files of some directories, parsed at load time. A type that
/// protobuf's generated pool has too (e.g. llsf_msgs.GameState, compiled into llsfsim) is the
/// generated one, after a check that it has every field of the file's type (number, name, type,
/// label); the others are built as
/// dynamic messages. Immutable after load(); shared by the games of a batch (thread-safe).
class ProtoLibrary {
 public:
  /// Parses every *.proto file of each directory (imports resolve within that directory).
  /// Throws core::ConfigError naming file:line:column for a parse error, and a type whose
  /// fields differ from the generated type of the same name.
  static std::shared_ptr<const ProtoLibrary> load(const std::vector<std::string>& dirs);
  ~ProtoLibrary();
  ProtoLibrary(const ProtoLibrary&) = delete;
  ProtoLibrary& operator=(const ProtoLibrary&) = delete;

  /// The dynamic types that declare `enum CompType { COMP_ID = ..; MSG_TYPE = ..; }`: what a
  /// game registers so that they travel over the radio. Prototypes live as long as the library.
  const std::vector<std::pair<MessageKey, const google::protobuf::Message*>>& types() const {
    return types_;
  }
  /// Registers types() in `registry`; throws core::ConfigError if a key is taken by another
  /// type (e.g. radio.lock_messages: 2013 puts llsfsim's lock messages at 2000/1337 and 1338).
  void register_in(MessageRegistry& registry) const;
  /// The full names of every message type the files define (dynamic or generated).
  const std::vector<std::string>& names() const { return names_; }

 private:
  ProtoLibrary();
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<std::pair<MessageKey, const google::protobuf::Message*>> types_;
  std::vector<std::string> names_;
};

}  // namespace llsf::comm
