// SPDX-License-Identifier: MIT
// The 2013 llsf_msgs schema against the spec (/work/shared/specs/llsf2013-rules.md §9.3-9.5):
// (COMP_ID, MSG_TYPE) of every message, every field's name/tag/type/label, every enum value.
// These tables are the second, independent transcription of the spec; the .proto files the first.
#include <doctest/doctest.h>
#include <google/protobuf/descriptor.pb.h>

#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "refbox/msgs/wire_util.h"

namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using llsf::msgs_test::all_message_types;

// ---------------------------------------------------------------------------------------------
// (a) Type registration, §9.3.

struct TypeRow {
  const Descriptor* descriptor;
  int spec_comp_id;
  int spec_msg_type;
  int cxx_comp_id;   // Msg::COMP_ID as generated
  int cxx_msg_type;  // Msg::MSG_TYPE as generated
};

#define LLSF_TYPE_ROW(Msg, comp, type)                                                             \
  TypeRow {                                                                                        \
    Msg::descriptor(), comp, type, static_cast<int>(Msg::COMP_ID), static_cast<int>(Msg::MSG_TYPE) \
  }

std::vector<TypeRow> spec_type_table() {
  using namespace llsf_msgs;
  return {
      LLSF_TYPE_ROW(BeaconSignal, 2000, 1),
      LLSF_TYPE_ROW(AttentionMessage, 2000, 2),
      LLSF_TYPE_ROW(VersionInfo, 2000, 3),
      LLSF_TYPE_ROW(SyncInfo, 2000, 5),
      LLSF_TYPE_ROW(InitiateSync, 2000, 6),
      LLSF_TYPE_ROW(LightSpec, 2000, 10),
      LLSF_TYPE_ROW(Machine, 2000, 12),
      LLSF_TYPE_ROW(MachineInfo, 2000, 13),
      LLSF_TYPE_ROW(RemovePuckFromMachine, 2000, 14),
      LLSF_TYPE_ROW(PlacePuckUnderMachine, 2000, 15),
      LLSF_TYPE_ROW(LoadPuckInMachine, 2000, 16),
      LLSF_TYPE_ROW(GameState, 2000, 20),
      LLSF_TYPE_ROW(SetGameState, 2000, 21),
      LLSF_TYPE_ROW(SetGamePhase, 2000, 22),
      LLSF_TYPE_ROW(RobotInfo, 2000, 30),
      LLSF_TYPE_ROW(Robot, 2000, 31),
      LLSF_TYPE_ROW(Order, 2000, 40),
      LLSF_TYPE_ROW(OrderInfo, 2000, 41),
      LLSF_TYPE_ROW(Puck, 2000, 50),
      LLSF_TYPE_ROW(PuckInfo, 2000, 51),
      LLSF_TYPE_ROW(SetPucks, 2000, 52),
      LLSF_TYPE_ROW(MachineReportEntry, 2000, 60),
      LLSF_TYPE_ROW(MachineReport, 2000, 61),
      LLSF_TYPE_ROW(MachineReportInfo, 2000, 62),
      LLSF_TYPE_ROW(ExplorationSignal, 2000, 70),
      LLSF_TYPE_ROW(ExplorationMachine, 2000, 71),
      LLSF_TYPE_ROW(ExplorationInfo, 2000, 72),
      LLSF_TYPE_ROW(GameInfo, 2000, 81),
      LLSF_TYPE_ROW(SetTeamName, 2000, 82),
      LLSF_TYPE_ROW(SetRobotMaintenance, 2000, 91),
      LLSF_TYPE_ROW(llsf_log_msgs::LogMessage, 2003, 1),
  };
}

#undef LLSF_TYPE_ROW

// §9.3: "Sub-messages without CompType (never sent alone)".
const std::set<std::string> kSubMessages = {
    "llsf_msgs.Time",
    "llsf_msgs.Pose2D",
    "llsf_msgs.MachineTypeSpec",
    "llsf_msgs.MachineTimeSpec",
    "llsf_msgs.MachineProcTime",
    "llsf_msgs.MachineLightSpec",
};

TEST_CASE("msgs: every top-level message has the spec's (COMP_ID, MSG_TYPE)") {
  const auto table = spec_type_table();
  CHECK(table.size() == 31);  // 30 llsf_msgs types + llsf_log_msgs.LogMessage
  std::set<std::pair<int, int>> seen;
  for (const auto& row : table) {
    CAPTURE(row.descriptor->full_name());
    CHECK(row.cxx_comp_id == row.spec_comp_id);
    CHECK(row.cxx_msg_type == row.spec_msg_type);
    // The CompType enum is nested in the message and has exactly the two values.
    const auto* comp_type = row.descriptor->FindEnumTypeByName("CompType");
    REQUIRE(comp_type != nullptr);
    CHECK(comp_type->value_count() == 2);
    REQUIRE(comp_type->FindValueByName("COMP_ID") != nullptr);
    REQUIRE(comp_type->FindValueByName("MSG_TYPE") != nullptr);
    CHECK(comp_type->FindValueByName("COMP_ID")->number() == row.spec_comp_id);
    CHECK(comp_type->FindValueByName("MSG_TYPE")->number() == row.spec_msg_type);
    CHECK(seen.insert({row.spec_comp_id, row.spec_msg_type}).second);  // unique
    // Packages: 2000 = llsf_msgs, 2003 = llsf_log_msgs.
    CHECK(row.descriptor->file()->package() ==
          (row.spec_comp_id == 2000 ? "llsf_msgs" : "llsf_log_msgs"));
  }
}

TEST_CASE("msgs: the files hold exactly the spec's messages; sub-messages have no CompType") {
  std::set<std::string> typed;
  for (const auto& row : spec_type_table()) typed.insert(row.descriptor->full_name());
  std::set<std::string> found;
  for (const auto* d : all_message_types()) {
    CAPTURE(d->full_name());
    found.insert(d->full_name());
    const bool is_typed = typed.count(d->full_name()) > 0;
    const bool is_sub = kSubMessages.count(d->full_name()) > 0;
    CHECK(is_typed != is_sub);  // exactly one of the two lists
    CHECK((d->FindEnumTypeByName("CompType") != nullptr) == is_typed);
    CHECK(d->containing_type() == nullptr);  // no nested messages in the 2013 files
  }
  CHECK(found.size() == typed.size() + kSubMessages.size());
  for (const auto& name : typed) CHECK_MESSAGE(found.count(name) == 1, name);
  for (const auto& name : kSubMessages) CHECK_MESSAGE(found.count(name) == 1, name);
}

TEST_CASE("msgs: the files are the spec's, with the spec's packages and Java package") {
  std::map<std::string, std::set<std::string>> spec_files = {
      {"llsf_msgs/Time.proto", {"Time"}},
      {"llsf_msgs/Pose2D.proto", {"Pose2D"}},
      {"llsf_msgs/BeaconSignal.proto", {"BeaconSignal"}},
      {"llsf_msgs/AttentionMessage.proto", {"AttentionMessage"}},
      {"llsf_msgs/VersionInfo.proto", {"VersionInfo"}},
      {"llsf_msgs/Sync.proto",
       {"SyncInfo", "InitiateSync", "MachineTypeSpec", "MachineTimeSpec", "MachineProcTime",
        "MachineLightSpec"}},
      {"llsf_msgs/MachineInfo.proto", {"LightSpec", "Machine", "MachineInfo"}},
      {"llsf_msgs/MachineCommands.proto",
       {"RemovePuckFromMachine", "PlacePuckUnderMachine", "LoadPuckInMachine"}},
      {"llsf_msgs/GameState.proto", {"GameState", "SetGameState", "SetGamePhase"}},
      {"llsf_msgs/RobotInfo.proto", {"RobotInfo", "Robot"}},
      {"llsf_msgs/OrderInfo.proto", {"Order", "OrderInfo"}},
      {"llsf_msgs/PuckInfo.proto", {"Puck", "PuckInfo", "SetPucks"}},
      {"llsf_msgs/MachineReport.proto",
       {"MachineReportEntry", "MachineReport", "MachineReportInfo"}},
      {"llsf_msgs/ExplorationInfo.proto",
       {"ExplorationSignal", "ExplorationMachine", "ExplorationInfo"}},
      {"llsf_msgs/GameInfo.proto", {"GameInfo", "SetTeamName"}},
      {"llsf_msgs/RobotCommands.proto", {"SetRobotMaintenance"}},
      {"llsf_log_msgs/LogMessage.proto", {"LogMessage"}},
  };
  const auto files = llsf::msgs_test::all_files();
  CHECK(files.size() == spec_files.size());
  for (const auto* f : files) {
    CAPTURE(f->name());
    REQUIRE(spec_files.count(f->name()) == 1);
    std::set<std::string> messages;
    for (int i = 0; i < f->message_type_count(); ++i) messages.insert(f->message_type(i)->name());
    CHECK(messages == spec_files[f->name()]);
    CHECK(f->syntax() == google::protobuf::FileDescriptor::SYNTAX_PROTO2);
    const bool log = f->name() == "llsf_log_msgs/LogMessage.proto";
    CHECK(f->package() == (log ? "llsf_log_msgs" : "llsf_msgs"));
    CHECK(f->options().java_package() ==
          (log ? "org.robocup_logistics.llsf_log_msgs" : "org.robocup_logistics.llsf_msgs"));
  }
}

// ---------------------------------------------------------------------------------------------
// Fields, §9.5: name, tag, label (R required, O optional, * repeated), type, and the message or
// enum type's full name where there is one.

struct FieldRow {
  const char* name;
  int tag;
  char label;
  FieldDescriptor::Type type;
  const char* type_name;  // "" for scalars
};

struct MessageRow {
  const char* message;
  std::vector<FieldRow> fields;
};

constexpr auto kI64 = FieldDescriptor::TYPE_INT64;
constexpr auto kU64 = FieldDescriptor::TYPE_UINT64;
constexpr auto kU32 = FieldDescriptor::TYPE_UINT32;
constexpr auto kF32 = FieldDescriptor::TYPE_FLOAT;
constexpr auto kBool = FieldDescriptor::TYPE_BOOL;
constexpr auto kStr = FieldDescriptor::TYPE_STRING;
constexpr auto kMsg = FieldDescriptor::TYPE_MESSAGE;
constexpr auto kEnum = FieldDescriptor::TYPE_ENUM;

const std::vector<MessageRow>& spec_fields() {
  static const std::vector<MessageRow> rows = {
      {"llsf_msgs.Time", {{"sec", 1, 'R', kI64, ""}, {"nsec", 2, 'R', kI64, ""}}},
      {"llsf_msgs.Pose2D",
       {{"timestamp", 1, 'R', kMsg, "llsf_msgs.Time"},
        {"x", 2, 'R', kF32, ""},
        {"y", 3, 'R', kF32, ""},
        {"ori", 4, 'R', kF32, ""}}},
      {"llsf_msgs.BeaconSignal",
       {{"time", 1, 'R', kMsg, "llsf_msgs.Time"},
        {"seq", 2, 'R', kU64, ""},
        {"team_name", 4, 'R', kStr, ""},
        {"peer_name", 5, 'R', kStr, ""},
        {"pose", 7, 'O', kMsg, "llsf_msgs.Pose2D"},
        {"number", 8, 'R', kU32, ""}}},
      {"llsf_msgs.AttentionMessage",
       {{"message", 1, 'R', kStr, ""}, {"time_to_show", 2, 'O', kF32, ""}}},
      {"llsf_msgs.VersionInfo",
       {{"version_major", 1, 'R', kU32, ""},
        {"version_minor", 2, 'R', kU32, ""},
        {"version_micro", 3, 'R', kU32, ""},
        {"version_string", 4, 'R', kStr, ""}}},
      {"llsf_msgs.LightSpec",
       {{"color", 1, 'R', kEnum, "llsf_msgs.LightColor"},
        {"state", 2, 'R', kEnum, "llsf_msgs.LightState"}}},
      {"llsf_msgs.Machine",
       {{"name", 1, 'R', kStr, ""},
        {"type", 2, 'O', kStr, ""},
        {"inputs", 3, '*', kEnum, "llsf_msgs.PuckState"},
        {"output", 4, 'O', kEnum, "llsf_msgs.PuckState"},
        {"loaded_with", 5, '*', kMsg, "llsf_msgs.Puck"},
        {"puck_under_rfid", 6, 'O', kMsg, "llsf_msgs.Puck"},
        {"lights", 7, '*', kMsg, "llsf_msgs.LightSpec"},
        {"pose", 8, 'O', kMsg, "llsf_msgs.Pose2D"},
        {"correctly_reported", 9, 'O', kBool, ""}}},
      {"llsf_msgs.MachineInfo", {{"machines", 1, '*', kMsg, "llsf_msgs.Machine"}}},
      {"llsf_msgs.RemovePuckFromMachine",
       {{"machine_name", 1, 'R', kStr, ""}, {"puck_id", 2, 'R', kU32, ""}}},
      {"llsf_msgs.PlacePuckUnderMachine",
       {{"machine_name", 1, 'R', kStr, ""}, {"puck_id", 2, 'R', kU32, ""}}},
      {"llsf_msgs.LoadPuckInMachine",
       {{"machine_name", 1, 'R', kStr, ""}, {"puck_id", 2, 'R', kU32, ""}}},
      {"llsf_msgs.GameState",
       {{"game_time", 1, 'R', kMsg, "llsf_msgs.Time"},
        {"state", 3, 'R', kEnum, "llsf_msgs.GameState.State"},
        {"phase", 4, 'R', kEnum, "llsf_msgs.GameState.Phase"},
        {"points", 5, 'O', kU32, ""},
        {"team", 6, 'O', kStr, ""},
        {"refbox_mode", 7, 'O', kEnum, "llsf_msgs.GameState.RefBoxMode"}}},
      {"llsf_msgs.SetGameState", {{"state", 1, 'R', kEnum, "llsf_msgs.GameState.State"}}},
      {"llsf_msgs.SetGamePhase", {{"phase", 1, 'R', kEnum, "llsf_msgs.GameState.Phase"}}},
      {"llsf_msgs.Robot",
       {{"name", 1, 'R', kStr, ""},
        {"team", 2, 'R', kStr, ""},
        {"host", 3, 'R', kStr, ""},
        {"last_seen", 4, 'R', kMsg, "llsf_msgs.Time"},
        {"pose", 6, 'O', kMsg, "llsf_msgs.Pose2D"},
        {"number", 7, 'R', kU32, ""},
        {"state", 8, 'O', kEnum, "llsf_msgs.RobotState"},
        {"maintenance_time_remaining", 9, 'O', kF32, ""},
        {"maintenance_cycles", 10, 'O', kU32, ""},
        {"vision_pose", 11, 'O', kMsg, "llsf_msgs.Pose2D"}}},
      {"llsf_msgs.RobotInfo", {{"robots", 1, '*', kMsg, "llsf_msgs.Robot"}}},
      {"llsf_msgs.Order",
       {{"id", 1, 'R', kU32, ""},
        {"product", 2, 'R', kEnum, "llsf_msgs.Order.ProductType"},
        {"quantity_requested", 3, 'R', kU32, ""},
        {"quantity_delivered", 4, 'R', kU32, ""},
        {"delivery_period_begin", 6, 'R', kU32, ""},
        {"delivery_period_end", 7, 'R', kU32, ""},
        {"delivery_gate", 8, 'O', kEnum, "llsf_msgs.Order.DeliveryGate"},
        {"late_order", 20, 'O', kBool, ""}}},
      {"llsf_msgs.OrderInfo", {{"orders", 1, '*', kMsg, "llsf_msgs.Order"}}},
      {"llsf_msgs.Puck",
       {{"id", 1, 'R', kU32, ""},
        {"state", 2, 'R', kEnum, "llsf_msgs.PuckState"},
        {"pose", 3, 'O', kMsg, "llsf_msgs.Pose2D"}}},
      {"llsf_msgs.PuckInfo", {{"pucks", 1, '*', kMsg, "llsf_msgs.Puck"}}},
      {"llsf_msgs.SetPucks", {{"ids", 1, '*', kU32, ""}}},
      {"llsf_msgs.MachineReportEntry", {{"name", 1, 'R', kStr, ""}, {"type", 2, 'R', kStr, ""}}},
      {"llsf_msgs.MachineReport", {{"machines", 1, '*', kMsg, "llsf_msgs.MachineReportEntry"}}},
      {"llsf_msgs.MachineReportInfo", {{"reported_machines", 1, '*', kStr, ""}}},
      {"llsf_msgs.ExplorationSignal",
       {{"type", 1, 'R', kStr, ""}, {"lights", 2, '*', kMsg, "llsf_msgs.LightSpec"}}},
      {"llsf_msgs.ExplorationMachine",
       {{"name", 1, 'R', kStr, ""}, {"pose", 2, 'R', kMsg, "llsf_msgs.Pose2D"}}},
      {"llsf_msgs.ExplorationInfo",
       {{"signals", 1, '*', kMsg, "llsf_msgs.ExplorationSignal"},
        {"machines", 2, '*', kMsg, "llsf_msgs.ExplorationMachine"}}},
      {"llsf_msgs.GameInfo", {{"known_teams", 1, '*', kStr, ""}}},
      {"llsf_msgs.SetTeamName", {{"team_name", 1, 'R', kStr, ""}}},
      {"llsf_msgs.SetRobotMaintenance",
       {{"robot_number", 1, 'R', kU32, ""}, {"maintenance", 3, 'R', kBool, ""}}},
      {"llsf_msgs.SyncInfo",
       {{"machines", 2, '*', kMsg, "llsf_msgs.MachineTypeSpec"},
        {"orders", 3, '*', kMsg, "llsf_msgs.Order"},
        {"down_times", 4, '*', kMsg, "llsf_msgs.MachineTimeSpec"},
        {"delivery_gates", 5, '*', kMsg, "llsf_msgs.MachineTimeSpec"},
        {"proc_times", 6, '*', kMsg, "llsf_msgs.MachineProcTime"},
        {"exploration_lights", 7, '*', kMsg, "llsf_msgs.MachineLightSpec"}}},
      {"llsf_msgs.InitiateSync", {}},
      {"llsf_msgs.MachineTypeSpec", {{"name", 1, 'R', kStr, ""}, {"type", 2, 'R', kStr, ""}}},
      {"llsf_msgs.MachineTimeSpec",
       {{"machine_name", 1, 'R', kStr, ""},
        {"gt_from", 2, 'R', kF32, ""},
        {"gt_to", 3, 'R', kF32, ""}}},
      {"llsf_msgs.MachineProcTime",
       {{"machine_type", 1, 'R', kStr, ""}, {"proc_time", 2, 'R', kU32, ""}}},
      {"llsf_msgs.MachineLightSpec",
       {{"machine_type", 1, 'R', kStr, ""}, {"lights", 2, '*', kMsg, "llsf_msgs.LightSpec"}}},
      {"llsf_log_msgs.LogMessage",
       {{"ts_sec", 1, 'R', kI64, ""},
        {"ts_nsec", 2, 'R', kI64, ""},
        {"log_level", 3, 'R', kEnum, "llsf_log_msgs.LogMessage.LogLevel"},
        {"component", 4, 'R', kStr, ""},
        {"message", 5, 'R', kStr, ""},
        {"is_exception", 6, 'O', kBool, ""}}},
  };
  return rows;
}

char label_char(const FieldDescriptor* f) {
  switch (f->label()) {
    case FieldDescriptor::LABEL_REQUIRED:
      return 'R';
    case FieldDescriptor::LABEL_OPTIONAL:
      return 'O';
    case FieldDescriptor::LABEL_REPEATED:
      return '*';
  }
  return '?';
}

TEST_CASE("msgs: every field has the spec's name, tag, label and type; nothing is packed") {
  const auto& rows = spec_fields();
  CHECK(rows.size() == 37);  // 31 typed messages + 6 sub-messages
  std::set<std::string> covered;
  for (const auto& row : rows) {
    CAPTURE(row.message);
    const auto* d =
        google::protobuf::DescriptorPool::generated_pool()->FindMessageTypeByName(row.message);
    REQUIRE(d != nullptr);
    covered.insert(row.message);
    CHECK(d->field_count() == static_cast<int>(row.fields.size()));
    for (const auto& spec : row.fields) {
      CAPTURE(spec.name);
      const auto* f = d->FindFieldByName(spec.name);
      REQUIRE(f != nullptr);
      CHECK(f->number() == spec.tag);
      CHECK(label_char(f) == spec.label);
      CHECK(f->type() == spec.type);
      CHECK(!f->is_packed());
      if (spec.type == kMsg) {
        CHECK(f->message_type()->full_name() == spec.type_name);
      } else if (spec.type == kEnum) {
        CHECK(f->enum_type()->full_name() == spec.type_name);
      } else {
        CHECK(std::string(spec.type_name).empty());
      }
    }
  }
  // Every message of the files has a row.
  for (const auto* d : all_message_types())
    CHECK_MESSAGE(covered.count(d->full_name()) == 1, d->full_name());
}

TEST_CASE("msgs: defaults of optional fields are the spec's") {
  llsf_msgs::GameState gs;
  CHECK(!gs.has_refbox_mode());
  CHECK(gs.refbox_mode() == llsf_msgs::GameState::STANDALONE);
  llsf_msgs::Order order;
  CHECK(!order.has_delivery_gate());
  CHECK(order.delivery_gate() == llsf_msgs::Order::ANY);
  CHECK(order.late_order() == false);
  llsf_msgs::Robot robot;
  CHECK(robot.maintenance_time_remaining() == 0.0f);
  CHECK(robot.maintenance_cycles() == 0);
  CHECK(robot.state() == llsf_msgs::ACTIVE);  // first value; RobotState has no 0
  llsf_log_msgs::LogMessage log;
  CHECK(log.is_exception() == false);
  llsf_msgs::Machine machine;
  CHECK(machine.output() == llsf_msgs::S0);
  CHECK(machine.correctly_reported() == false);
  llsf_msgs::AttentionMessage attention;
  CHECK(attention.time_to_show() == 0.0f);
}

// ---------------------------------------------------------------------------------------------
// (e) Enum values, §9.4.

struct EnumRow {
  const char* enum_name;
  std::vector<std::pair<const char*, int>> values;
};

TEST_CASE("msgs: every enum has exactly the spec's values") {
  const std::vector<EnumRow> rows = {
      {"llsf_msgs.GameState.State",
       {{"INIT", 0}, {"WAIT_START", 1}, {"RUNNING", 2}, {"PAUSED", 3}}},
      {"llsf_msgs.GameState.Phase",
       {{"PRE_GAME", 0},
        {"SETUP", 10},
        {"EXPLORATION", 20},
        {"PRODUCTION", 30},
        {"POST_GAME", 40},
        {"OPEN_CHALLENGE", 1000},
        {"NAVIGATION_CHALLENGE", 1001},
        {"WHACK_A_MOLE_CHALLENGE", 1002}}},
      {"llsf_msgs.GameState.RefBoxMode", {{"STANDALONE", 0}, {"MASTER", 1}, {"SLAVE", 2}}},
      {"llsf_msgs.LightColor", {{"RED", 0}, {"YELLOW", 1}, {"GREEN", 2}}},
      {"llsf_msgs.LightState", {{"OFF", 0}, {"ON", 1}, {"BLINK", 2}}},
      {"llsf_msgs.PuckState",
       {{"S0", 0},
        {"S1", 1},
        {"S2", 2},
        {"P1", 4},
        {"P2", 5},
        {"P3", 6},
        {"CONSUMED", 7},
        {"FINISHED", 8}}},
      {"llsf_msgs.RobotState", {{"ACTIVE", 1}, {"MAINTENANCE", 2}, {"DISQUALIFIED", 3}}},
      {"llsf_msgs.Order.ProductType", {{"P1", 1}, {"P2", 2}, {"P3", 3}}},
      {"llsf_msgs.Order.DeliveryGate", {{"ANY", 1}, {"D1", 2}, {"D2", 3}, {"D3", 4}}},
      {"llsf_log_msgs.LogMessage.LogLevel",
       {{"LL_DEBUG", 0}, {"LL_INFO", 1}, {"LL_WARN", 2}, {"LL_ERROR", 4}, {"LL_NONE", 8}}},
  };
  for (const auto& row : rows) {
    CAPTURE(row.enum_name);
    const auto* e =
        google::protobuf::DescriptorPool::generated_pool()->FindEnumTypeByName(row.enum_name);
    REQUIRE(e != nullptr);
    CHECK(e->value_count() == static_cast<int>(row.values.size()));
    // Not a structured binding: CAPTURE's lambda cannot capture one before clang 16 (clang-tidy).
    for (const auto& value : row.values) {
      const auto& name = value.first;
      CAPTURE(name);
      const auto* v = e->FindValueByName(name);
      REQUIRE(v != nullptr);
      CHECK(v->number() == value.second);
    }
    // Declared in the spec's order: the first value is the default of an unset optional field.
    CHECK(std::string(e->value(0)->name()) == row.values.front().first);
  }
  // The same numbers as generated C++ constants, and the gaps.
  CHECK(llsf_msgs::S2 == 2);
  CHECK(llsf_msgs::P1 == 4);
  CHECK(llsf_msgs::FINISHED == 8);
  CHECK(!llsf_msgs::PuckState_IsValid(3));
  CHECK(llsf_msgs::GameState::PRODUCTION == 30);
  CHECK(llsf_msgs::GameState::WHACK_A_MOLE_CHALLENGE == 1002);
  CHECK(!llsf_msgs::GameState::Phase_IsValid(1));  // the 0.5.x EXPLORATION number
  CHECK(llsf_msgs::Order::ANY == 1);
  CHECK(llsf_msgs::Order::P3 == 3);
  CHECK(!llsf_msgs::Order::DeliveryGate_IsValid(0));
  CHECK(llsf_msgs::BLINK == 2);
  CHECK(llsf_msgs::GREEN == 2);
  CHECK(llsf_msgs::DISQUALIFIED == 3);
  CHECK(!llsf_msgs::RobotState_IsValid(0));
  CHECK(llsf_log_msgs::LogMessage::LL_ERROR == 4);
  CHECK(!llsf_log_msgs::LogMessage::LogLevel_IsValid(3));
}

}  // namespace
