// SPDX-License-Identifier: MIT
// Helpers for the llsf_msgs tests: hex <-> bytes, and the list of every 2013 message type.
#pragma once

#include <llsf_log_msgs/LogMessage.pb.h>
#include <llsf_msgs/AttentionMessage.pb.h>
#include <llsf_msgs/BeaconSignal.pb.h>
#include <llsf_msgs/ExplorationInfo.pb.h>
#include <llsf_msgs/GameInfo.pb.h>
#include <llsf_msgs/GameState.pb.h>
#include <llsf_msgs/MachineCommands.pb.h>
#include <llsf_msgs/MachineInfo.pb.h>
#include <llsf_msgs/MachineReport.pb.h>
#include <llsf_msgs/OrderInfo.pb.h>
#include <llsf_msgs/Pose2D.pb.h>
#include <llsf_msgs/PuckInfo.pb.h>
#include <llsf_msgs/RobotCommands.pb.h>
#include <llsf_msgs/RobotInfo.pb.h>
#include <llsf_msgs/Sync.pb.h>
#include <llsf_msgs/Time.pb.h>
#include <llsf_msgs/VersionInfo.pb.h>

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace llsf::msgs_test {

/// Bytes from a readable spec: hex pairs, and ASCII text in double quotes, whitespace ignored:
/// bytes(R"(0a 02 "M1")") == "\x0a\x02M1". Throws std::invalid_argument on bad input.
inline std::string bytes(std::string_view spec) {
  auto fail = [spec](const char* what) {
    throw std::invalid_argument(std::string(what) + " in \"" + std::string(spec) + "\"");
  };
  auto nibble = [&fail](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    fail("bad hex digit");
    return 0;
  };
  std::string out;
  int high = -1;
  bool in_text = false;
  for (char c : spec) {
    if (in_text) {
      if (c == '"') {
        in_text = false;
      } else {
        out.push_back(c);
      }
    } else if (c == '"') {
      if (high >= 0) fail("text inside a hex pair");
      in_text = true;
    } else if (c == ' ' || c == '\n') {
      if (high >= 0) fail("space inside a hex pair");
    } else if (high < 0) {
      high = nibble(c);
    } else {
      out.push_back(static_cast<char>(high * 16 + nibble(c)));
      high = -1;
    }
  }
  if (high >= 0 || in_text) fail("unterminated hex pair or text");
  return out;
}

/// Lower-case hex pairs separated by spaces, for readable failure messages.
inline std::string to_hex(std::string_view b) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  for (unsigned char c : b) {
    if (!out.empty()) out.push_back(' ');
    out.push_back(kDigits[c >> 4]);
    out.push_back(kDigits[c & 0xf]);
  }
  return out;
}

/// Every .proto file of the 2013 messages (one descriptor of each; linking them in).
inline std::vector<const google::protobuf::FileDescriptor*> all_files() {
  return {
      llsf_msgs::Time::descriptor()->file(),
      llsf_msgs::Pose2D::descriptor()->file(),
      llsf_msgs::BeaconSignal::descriptor()->file(),
      llsf_msgs::AttentionMessage::descriptor()->file(),
      llsf_msgs::VersionInfo::descriptor()->file(),
      llsf_msgs::SyncInfo::descriptor()->file(),
      llsf_msgs::MachineInfo::descriptor()->file(),
      llsf_msgs::LoadPuckInMachine::descriptor()->file(),
      llsf_msgs::GameState::descriptor()->file(),
      llsf_msgs::RobotInfo::descriptor()->file(),
      llsf_msgs::OrderInfo::descriptor()->file(),
      llsf_msgs::PuckInfo::descriptor()->file(),
      llsf_msgs::MachineReport::descriptor()->file(),
      llsf_msgs::ExplorationInfo::descriptor()->file(),
      llsf_msgs::GameInfo::descriptor()->file(),
      llsf_msgs::SetRobotMaintenance::descriptor()->file(),
      llsf_log_msgs::LogMessage::descriptor()->file(),
  };
}

/// Every message type declared in those files, nested ones included.
inline std::vector<const google::protobuf::Descriptor*> all_message_types() {
  std::vector<const google::protobuf::Descriptor*> out;
  std::vector<const google::protobuf::Descriptor*> todo;
  for (const auto* f : all_files()) {
    for (int i = 0; i < f->message_type_count(); ++i) todo.push_back(f->message_type(i));
  }
  while (!todo.empty()) {
    const auto* d = todo.back();
    todo.pop_back();
    out.push_back(d);
    for (int i = 0; i < d->nested_type_count(); ++i) todo.push_back(d->nested_type(i));
  }
  return out;
}

}  // namespace llsf::msgs_test
