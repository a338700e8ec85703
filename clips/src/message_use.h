// SPDX-License-Identifier: MIT
// Which received messages an agent's rules can match at all: the protobuf feature asserts no
// protobuf-msg fact for the other types (docs/clips.md, "Messages").
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <span>
#include <string>

namespace llsf::clips::detail {

/// A set of message type names (protobuf full names) that finds string_views too.
using TypeNames = std::set<std::string, std::less<>>;

/// The message types that the constructs (their pretty-print texts: Environment::
/// construct_texts) can see as protobuf-msg facts, when every mention of protobuf-msg is a
/// rule's pattern naming one type as a string -- (protobuf-msg (type "llsf_msgs.GameState") ...),
/// also inside not, exists, or, ... -- and no construct reaches facts another way. Otherwise
/// std::nullopt: every type may be seen. That is the case for a pattern without a type or with
/// any other type constraint ((type ?t), (type "A"|"B")), protobuf-msg anywhere else (a fact
/// query, a deffunction, a rule's actions, a string), and the functions that read or make code
/// or facts by text: build, eval, facts, get-fact-list.
std::optional<TypeNames> matched_message_types(std::span<const std::string> construct_texts);

}  // namespace llsf::clips::detail
