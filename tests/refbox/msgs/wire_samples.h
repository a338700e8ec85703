// SPDX-License-Identifier: MIT
// One or more representative instances of every 2013 message, each with its wire bytes computed
// by hand from the spec (§9.5) and the protobuf encoding rules — not by protoc.
//
// Encoding rules used below (protobuf wire format, proto2):
//   key = (tag << 3) | wire_type; wire types 0 varint, 2 length-delimited, 5 fixed32.
//   key bytes: tag 1 -> 08 (varint) / 0a (len) / 0d (fixed32); tag 2 -> 10/12/15; tag 3 ->
//   18/1a/1d; tag 4 -> 20/22/25; tag 5 -> 28/2a; tag 6 -> 30/32; tag 7 -> 38/3a; tag 8 -> 40/42;
//   tag 9 -> 48/4d; tag 10 -> 50; tag 11 -> 5a; tag 20 varint -> 160 = a0 01 (two-byte key).
//   varint: 7 bits per byte, least significant group first, 0x80 = more follows.
//   int64/uint32/uint64/enum/bool: plain varint (no zigzag); a negative int64 is its 64-bit two's
//   complement, always 10 bytes.
//   float: fixed32, IEEE 754 single, little endian.
//   string / sub-message: key, varint length, bytes.
//   repeated scalars/enums: not packed in proto2 unless [packed=true] (never in 2013): one key
//   per element.
//   fields are written in tag order; set proto2 fields are written even when 0.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "refbox/msgs/wire_util.h"

namespace llsf::msgs_test {

/// A message instance and the bytes it must serialize to.
struct Sample {
  std::string label;
  std::function<std::unique_ptr<google::protobuf::Message>()> make;
  std::string expected;  // wire bytes
};

template <class M, class Fill>
Sample sample(std::string label, Fill fill, std::string_view wire) {
  return Sample{std::move(label),
                [fill]() -> std::unique_ptr<google::protobuf::Message> {
                  auto m = std::make_unique<M>();
                  fill(*m);
                  return m;
                },
                bytes(wire)};
}

inline void set_time(llsf_msgs::Time* t, std::int64_t sec, std::int64_t nsec) {
  t->set_sec(sec);
  t->set_nsec(nsec);
}

// Pose A: timestamp {1 s, 2 ns}, x 1.5 m, y -0.5 m, ori 3.0 rad.
inline void set_pose_a(llsf_msgs::Pose2D* p) {
  set_time(p->mutable_timestamp(), 1, 2);
  p->set_x(1.5f);
  p->set_y(-0.5f);
  p->set_ori(3.0f);
}
// 21 bytes:
//   0a 04 | 08 01 10 02      timestamp (tag 1, len 4): sec 1, nsec 2
//   15 00 00 c0 3f           x: 1.5 = 1.1b * 2^0 -> sign 0, exponent 127 (0x7f), mantissa .1b
//                            -> 0 01111111 100... = 0x3fc00000 -> little endian 00 00 c0 3f
//   1d 00 00 00 bf           y: -0.5 = -1.0b * 2^-1 -> 1 01111110 000... = 0xbf000000
//   25 00 00 40 40           ori: 3.0 = 1.1b * 2^1 -> 0 10000000 100... = 0x40400000
#define LLSF_POSE_A "0a 04 08 01 10 02 15 00 00 c0 3f 1d 00 00 00 bf 25 00 00 40 40"

// Pose B: timestamp {5 s, 0 ns}, x 4.5 m, y 1.0 m, ori 0.0 rad.
inline void set_pose_b(llsf_msgs::Pose2D* p) {
  set_time(p->mutable_timestamp(), 5, 0);
  p->set_x(4.5f);
  p->set_y(1.0f);
  p->set_ori(0.0f);
}
// 21 bytes: 4.5 = 1.001b * 2^2 -> 0 10000001 001... = 0x40900000; 1.0 = 0x3f800000; 0.0 = 0 (a set
// required float is written even when 0).
#define LLSF_POSE_B "0a 04 08 05 10 00 15 00 00 90 40 1d 00 00 80 3f 25 00 00 00 00"

inline void set_light(llsf_msgs::LightSpec* l, llsf_msgs::LightColor c, llsf_msgs::LightState s) {
  l->set_color(c);
  l->set_state(s);
}

inline void set_order(llsf_msgs::Order* o, int id, llsf_msgs::Order::ProductType product,
                      int requested, int delivered, int begin, int end) {
  o->set_id(static_cast<std::uint32_t>(id));
  o->set_product(product);
  o->set_quantity_requested(static_cast<std::uint32_t>(requested));
  o->set_quantity_delivered(static_cast<std::uint32_t>(delivered));
  o->set_delivery_period_begin(static_cast<std::uint32_t>(begin));
  o->set_delivery_period_end(static_cast<std::uint32_t>(end));
}

/// Every message type at least once (a test checks the coverage).
inline const std::vector<Sample>& samples() {
  using namespace llsf_msgs;
  static const std::vector<Sample> all = {
      // Time: 1372723200 (2013-07-02 00:00:00 UTC) = 5*128^4 + 14*128^3 + 72*128^2 + 48*128 + 0
      //   -> groups 0, 48, 72, 14, 5 -> 80 b0 c8 8e 05.
      // 500000000 = 1*128^4 + 110*128^3 + 53*128^2 + 74*128 + 0 -> 80 ca b5 ee 01.
      sample<Time>(
          "Time (epoch)", [](Time& m) { set_time(&m, 1372723200, 500000000); },
          "08 80 b0 c8 8e 05  10 80 ca b5 ee 01"),
      // Negative int64, no zigzag: -300 = 0xffff_ffff_ffff_fed4; 7-bit groups from the bottom:
      //   0x54, 0x7d, then seven groups of 0x7f, then the 64th bit: 1
      //   -> d4 fd ff ff ff ff ff ff ff 01 (10 bytes). -1 -> nine ff then 01.
      sample<Time>(
          "Time (negative)", [](Time& m) { set_time(&m, -300, -1); },
          "08 d4 fd ff ff ff ff ff ff ff 01  10 ff ff ff ff ff ff ff ff ff 01"),
      sample<Pose2D>(
          "Pose2D", [](Pose2D& m) { set_pose_a(&m); }, LLSF_POSE_A),
      // Robot beacon. time: 12 bytes (see Time) -> 0a 0c; seq 300 = 2*128 + 44 -> ac 02;
      // pose (tag 7): timestamp {0, 0} is written (set), 2.0 = 0x40000000, 0.25 = 1.0b * 2^-2 ->
      // 0 01111101 0... = 0x3e800000, -1.0 = 0xbf800000 -> 21 bytes -> 3a 15.
      sample<BeaconSignal>(
          "BeaconSignal (robot)",
          [](BeaconSignal& m) {
            set_time(m.mutable_time(), 1372723200, 500000000);
            m.set_seq(300);
            m.set_team_name("Carologistics");
            m.set_peer_name("R-1");
            set_time(m.mutable_pose()->mutable_timestamp(), 0, 0);
            m.mutable_pose()->set_x(2.0f);
            m.mutable_pose()->set_y(0.25f);
            m.mutable_pose()->set_ori(-1.0f);
            m.set_number(1);
          },
          R"(0a 0c 08 80 b0 c8 8e 05 10 80 ca b5 ee 01
             10 ac 02
             22 0d "Carologistics"
             2a 03 "R-1"
             3a 15 0a 04 08 00 10 00 15 00 00 00 40 1d 00 00 80 3e 25 00 00 80 bf
             40 01)"),
      // The refbox's own beacon (§9.6): number 0 is written because it is set (required).
      sample<BeaconSignal>(
          "BeaconSignal (refbox)",
          [](BeaconSignal& m) {
            set_time(m.mutable_time(), 5, 0);
            m.set_seq(0);
            m.set_team_name("LLSF");
            m.set_peer_name("RefBox");
            m.set_number(0);
          },
          R"(0a 04 08 05 10 00  10 00  22 04 "LLSF"  2a 06 "RefBox"  40 00)"),
      // 10.0 = 1.01b * 2^3 -> 0 10000010 01... = 0x41200000 -> 00 00 20 41.
      sample<AttentionMessage>(
          "AttentionMessage",
          [](AttentionMessage& m) {
            m.set_message("Robot lost");
            m.set_time_to_show(10.0f);
          },
          R"(0a 0a "Robot lost"  15 00 00 20 41)"),
      sample<AttentionMessage>(
          "AttentionMessage (no time_to_show)", [](AttentionMessage& m) { m.set_message("x"); },
          R"(0a 01 "x")"),
      sample<VersionInfo>(
          "VersionInfo",
          [](VersionInfo& m) {
            m.set_version_major(0);
            m.set_version_minor(6);
            m.set_version_micro(1);
            m.set_version_string("0.6.1");
          },
          R"(08 00  10 06  18 01  22 05 "0.6.1")"),
      sample<LightSpec>(
          "LightSpec", [](LightSpec& m) { set_light(&m, YELLOW, BLINK); }, "08 01 10 02"),
      // Machine: the repeated enum `inputs` (tag 3) is not packed: 18 00 18 01 18 02, one key each.
      // output P1 = 4 (PuckState has no 3). loaded_with/puck_under_rfid: Puck sub-messages of 4
      // bytes (08 id 10 state). lights: two LightSpecs of 4 bytes. pose: Pose A, 21 = 0x15 bytes.
      sample<Machine>(
          "Machine",
          [](Machine& m) {
            m.set_name("M5");
            m.set_type("T3");
            m.add_inputs(S0);
            m.add_inputs(S1);
            m.add_inputs(S2);
            m.set_output(P1);
            auto* loaded = m.add_loaded_with();
            loaded->set_id(3);
            loaded->set_state(CONSUMED);
            m.mutable_puck_under_rfid()->set_id(7);
            m.mutable_puck_under_rfid()->set_state(S2);
            set_light(m.add_lights(), RED, ON);
            set_light(m.add_lights(), GREEN, BLINK);
            set_pose_a(m.mutable_pose());
            m.set_correctly_reported(true);
          },
          R"(0a 02 "M5"
             12 02 "T3"
             18 00 18 01 18 02
             20 04
             2a 04 08 03 10 07
             32 04 08 07 10 02
             3a 04 08 00 10 01  3a 04 08 02 10 02
             42 15 )" LLSF_POSE_A R"(
             48 01)"),
      // MachineInfo: Machine{D1, DELIVER} = 0a 02 "D1" 12 07 "DELIVER" = 13 bytes -> 0a 0d;
      // Machine{M2} = 4 bytes -> 0a 04.
      sample<MachineInfo>(
          "MachineInfo",
          [](MachineInfo& m) {
            auto* d1 = m.add_machines();
            d1->set_name("D1");
            d1->set_type("DELIVER");
            m.add_machines()->set_name("M2");
          },
          R"(0a 0d 0a 02 "D1" 12 07 "DELIVER"  0a 04 0a 02 "M2")"),
      sample<MachineInfo>(
          "MachineInfo (empty)", [](MachineInfo&) {}, ""),
      sample<RemovePuckFromMachine>(
          "RemovePuckFromMachine",
          [](RemovePuckFromMachine& m) {
            m.set_machine_name("M1");
            m.set_puck_id(12);
          },
          R"(0a 02 "M1" 10 0c)"),
      // 200 = 1*128 + 72 -> c8 01.
      sample<PlacePuckUnderMachine>(
          "PlacePuckUnderMachine",
          [](PlacePuckUnderMachine& m) {
            m.set_machine_name("M2");
            m.set_puck_id(200);
          },
          R"(0a 02 "M2" 10 c8 01)"),
      sample<LoadPuckInMachine>(
          "LoadPuckInMachine",
          [](LoadPuckInMachine& m) {
            m.set_machine_name("M3");
            m.set_puck_id(1);
          },
          R"(0a 02 "M3" 10 01)"),
      // GameState: game_time {300, 0}: 300 = 2*128 + 44 -> ac 02; 5 bytes -> 0a 05. Tag 2 unused,
      // state (tag 3) RUNNING 2 -> 18 02; phase (tag 4) PRODUCTION 30 -> 20 1e; points 42 -> 28 2a;
      // team (tag 6) -> 32 0d; refbox_mode MASTER 1 -> 38 01.
      sample<GameState>(
          "GameState",
          [](GameState& m) {
            set_time(m.mutable_game_time(), 300, 0);
            m.set_state(GameState::RUNNING);
            m.set_phase(GameState::PRODUCTION);
            m.set_points(42);
            m.set_team("Carologistics");
            m.set_refbox_mode(GameState::MASTER);
          },
          R"(0a 05 08 ac 02 10 00  18 02  20 1e  28 2a  32 0d "Carologistics"  38 01)"),
      // The UDP copy: no refbox_mode, no team, no points; INIT and PRE_GAME are 0 but written.
      sample<GameState>(
          "GameState (minimal)",
          [](GameState& m) {
            set_time(m.mutable_game_time(), 0, 0);
            m.set_state(GameState::INIT);
            m.set_phase(GameState::PRE_GAME);
          },
          "0a 04 08 00 10 00  18 00  20 00"),
      sample<SetGameState>(
          "SetGameState", [](SetGameState& m) { m.set_state(GameState::PAUSED); }, "08 03"),
      // 1001 = 7*128 + 105 -> (105 | 0x80) = e9, 07.
      sample<SetGamePhase>(
          "SetGamePhase", [](SetGamePhase& m) { m.set_phase(GameState::NAVIGATION_CHALLENGE); },
          "08 e9 07"),
      // Robot: last_seen {5, 250000000}; 250000000 = 119*128^3 + 26*128^2 + 101*128 + 0
      //   -> 80 e5 9a 77; 7 bytes -> 22 07. Tag 5 unused: pose is tag 6 (32), number tag 7 (38),
      //   state tag 8 (40) MAINTENANCE 2, maintenance_time_remaining tag 9 fixed32 (4d):
      //   -12.5 = -1.1001b * 2^3 -> 1 10000010 1001... = 0xc1480000 -> 00 00 48 c1;
      //   maintenance_cycles tag 10 (50); vision_pose tag 11 (5a).
      sample<Robot>(
          "Robot",
          [](Robot& m) {
            m.set_name("R-1");
            m.set_team("Carologistics");
            m.set_host("172.26.1.11");
            set_time(m.mutable_last_seen(), 5, 250000000);
            set_pose_b(m.mutable_pose());
            m.set_number(2);
            m.set_state(MAINTENANCE);
            m.set_maintenance_time_remaining(-12.5f);
            m.set_maintenance_cycles(1);
            set_pose_b(m.mutable_vision_pose());
          },
          R"(0a 03 "R-1"
             12 0d "Carologistics"
             1a 0b "172.26.1.11"
             22 07 08 05 10 80 e5 9a 77
             32 15 )" LLSF_POSE_B R"(
             38 02
             40 02
             4d 00 00 48 c1
             50 01
             5a 15 )" LLSF_POSE_B),
      // RobotInfo: one Robot of 5 + 3 + 3 + 6 + 2 = 19 = 0x13 bytes.
      sample<RobotInfo>(
          "RobotInfo",
          [](RobotInfo& m) {
            auto* r = m.add_robots();
            r->set_name("R-2");
            r->set_team("T");
            r->set_host("h");
            set_time(r->mutable_last_seen(), 0, 0);
            r->set_number(3);
          },
          R"(0a 13  0a 03 "R-2"  12 01 "T"  1a 01 "h"  22 04 08 00 10 00  38 03)"),
      // Order: tag 5 unused; begin 120 -> 30 78; end 300 -> 38 ac 02; gate D2 = 3 -> 40 03;
      // late_order is tag 20: key 20 << 3 | 0 = 160 = 1*128 + 32 -> a0 01, then value 01.
      sample<Order>(
          "Order",
          [](Order& m) {
            set_order(&m, 1, Order::P3, 2, 0, 120, 300);
            m.set_delivery_gate(Order::D2);
            m.set_late_order(true);
          },
          "08 01  10 03  18 02  20 00  30 78  38 ac 02  40 03  a0 01 01"),
      // OrderInfo: 900 = 7*128 + 4 -> 84 07; 600 = 4*128 + 88 -> d8 04.
      //   order 2: 2+2+2+2+2+3 = 13 bytes -> 0a 0d; order 3 (gate D3 = 4): 16 bytes -> 0a 10.
      sample<OrderInfo>(
          "OrderInfo",
          [](OrderInfo& m) {
            set_order(m.add_orders(), 2, Order::P1, 1, 1, 0, 900);
            auto* o = m.add_orders();
            set_order(o, 3, Order::P2, 1, 0, 600, 900);
            o->set_delivery_gate(Order::D3);
          },
          R"(0a 0d 08 02 10 01 18 01 20 01 30 00 38 84 07
             0a 10 08 03 10 02 18 01 20 00 30 d8 04 38 84 07 40 04)"),
      sample<Puck>(
          "Puck",
          [](Puck& m) {
            m.set_id(4);
            m.set_state(P1);
          },
          "08 04 10 04"),
      sample<Puck>(
          "Puck (with pose)",
          [](Puck& m) {
            m.set_id(16);
            m.set_state(FINISHED);
            set_pose_a(m.mutable_pose());
          },
          "08 10  10 08  1a 15 " LLSF_POSE_A),
      sample<PuckInfo>(
          "PuckInfo",
          [](PuckInfo& m) {
            auto* a = m.add_pucks();
            a->set_id(1);
            a->set_state(S0);
            auto* b = m.add_pucks();
            b->set_id(2);
            b->set_state(FINISHED);
          },
          "0a 04 08 01 10 00  0a 04 08 02 10 08"),
      // Repeated uint32, not packed: one key (08) per element; 300 -> ac 02.
      sample<SetPucks>(
          "SetPucks",
          [](SetPucks& m) {
            m.add_ids(1);
            m.add_ids(20);
            m.add_ids(300);
          },
          "08 01  08 14  08 ac 02"),
      sample<MachineReportEntry>(
          "MachineReportEntry",
          [](MachineReportEntry& m) {
            m.set_name("M3");
            m.set_type("T2");
          },
          R"(0a 02 "M3" 12 02 "T2")"),
      sample<MachineReport>(
          "MachineReport",
          [](MachineReport& m) {
            auto* a = m.add_machines();
            a->set_name("M3");
            a->set_type("T2");
            auto* b = m.add_machines();
            b->set_name("M7");
            b->set_type("T5");
          },
          R"(0a 08 0a 02 "M3" 12 02 "T2"  0a 08 0a 02 "M7" 12 02 "T5")"),
      sample<MachineReportInfo>(
          "MachineReportInfo",
          [](MachineReportInfo& m) {
            m.add_reported_machines("M3");
            m.add_reported_machines("M7");
          },
          R"(0a 02 "M3"  0a 02 "M7")"),
      sample<ExplorationSignal>(
          "ExplorationSignal",
          [](ExplorationSignal& m) {
            m.set_type("T1");
            set_light(m.add_lights(), RED, ON);
            set_light(m.add_lights(), YELLOW, OFF);
            set_light(m.add_lights(), GREEN, BLINK);
          },
          R"(0a 02 "T1"  12 04 08 00 10 01  12 04 08 01 10 00  12 04 08 02 10 02)"),
      sample<ExplorationMachine>(
          "ExplorationMachine",
          [](ExplorationMachine& m) {
            m.set_name("M1");
            set_pose_a(m.mutable_pose());
          },
          R"(0a 02 "M1"  12 15 )" LLSF_POSE_A),
      // ExplorationInfo: signal = 4 + 6 = 10 bytes -> 0a 0a; machine = 4 + 2 + 21 = 27 -> 12 1b.
      sample<ExplorationInfo>(
          "ExplorationInfo",
          [](ExplorationInfo& m) {
            auto* s = m.add_signals();
            s->set_type("T1");
            set_light(s->add_lights(), RED, ON);
            auto* e = m.add_machines();
            e->set_name("M1");
            set_pose_a(e->mutable_pose());
          },
          R"(0a 0a 0a 02 "T1" 12 04 08 00 10 01
             12 1b 0a 02 "M1" 12 15 )" LLSF_POSE_A),
      sample<GameInfo>(
          "GameInfo",
          [](GameInfo& m) {
            m.add_known_teams("Carologistics");
            m.add_known_teams("Solidus");
          },
          R"(0a 0d "Carologistics"  0a 07 "Solidus")"),
      sample<SetTeamName>(
          "SetTeamName", [](SetTeamName& m) { m.set_team_name("Carologistics"); },
          R"(0a 0d "Carologistics")"),
      // Tag 2 unused: maintenance is tag 3 -> 18.
      sample<SetRobotMaintenance>(
          "SetRobotMaintenance",
          [](SetRobotMaintenance& m) {
            m.set_robot_number(2);
            m.set_maintenance(true);
          },
          "08 02  18 01"),
      // SyncInfo: tag 1 unused, machines is tag 2 (12 ..). Floats: 100.0 = 1.1001b * 2^6 ->
      // 0 10000101 1001... = 0x42c80000; 220.0 = 1.10111b * 2^7 -> 0 10000110 10111... =
      // 0x435c0000; 180.0 = 1.01101b * 2^7 -> 0 10000110 01101... = 0x43340000.
      sample<SyncInfo>(
          "SyncInfo",
          [](SyncInfo& m) {
            auto* type = m.add_machines();
            type->set_name("M1");
            type->set_type("T3");
            set_order(m.add_orders(), 1, Order::P1, 1, 0, 0, 900);
            auto* down = m.add_down_times();
            down->set_machine_name("M1");
            down->set_gt_from(100.0f);
            down->set_gt_to(220.0f);
            auto* gate = m.add_delivery_gates();
            gate->set_machine_name("D1");
            gate->set_gt_from(0.0f);
            gate->set_gt_to(180.0f);
            auto* proc = m.add_proc_times();
            proc->set_machine_type("T1");
            proc->set_proc_time(4);
            auto* lights = m.add_exploration_lights();
            lights->set_machine_type("T1");
            set_light(lights->add_lights(), RED, ON);
          },
          R"(12 08 0a 02 "M1" 12 02 "T3"
             1a 0d 08 01 10 01 18 01 20 00 30 00 38 84 07
             22 0e 0a 02 "M1" 15 00 00 c8 42 1d 00 00 5c 43
             2a 0e 0a 02 "D1" 15 00 00 00 00 1d 00 00 34 43
             32 06 0a 02 "T1" 10 04
             3a 0a 0a 02 "T1" 12 04 08 00 10 01)"),
      sample<InitiateSync>(
          "InitiateSync", [](InitiateSync&) {}, ""),
      sample<MachineTypeSpec>(
          "MachineTypeSpec",
          [](MachineTypeSpec& m) {
            m.set_name("M1");
            m.set_type("T3");
          },
          R"(0a 02 "M1" 12 02 "T3")"),
      sample<MachineTimeSpec>(
          "MachineTimeSpec",
          [](MachineTimeSpec& m) {
            m.set_machine_name("M4");
            m.set_gt_from(100.0f);
            m.set_gt_to(220.0f);
          },
          R"(0a 02 "M4"  15 00 00 c8 42  1d 00 00 5c 43)"),
      sample<MachineProcTime>(
          "MachineProcTime",
          [](MachineProcTime& m) {
            m.set_machine_type("T5");
            m.set_proc_time(25);
          },
          R"(0a 02 "T5"  10 19)"),
      sample<MachineLightSpec>(
          "MachineLightSpec",
          [](MachineLightSpec& m) {
            m.set_machine_type("T2");
            set_light(m.add_lights(), RED, OFF);
            set_light(m.add_lights(), YELLOW, ON);
            set_light(m.add_lights(), GREEN, ON);
          },
          R"(0a 02 "T2"  12 04 08 00 10 00  12 04 08 01 10 01  12 04 08 02 10 01)"),
      // LogMessage: ts as in "Time (epoch)"; LL_ERROR = 4 -> 18 04.
      sample<llsf_log_msgs::LogMessage>(
          "LogMessage",
          [](llsf_log_msgs::LogMessage& m) {
            m.set_ts_sec(1372723200);
            m.set_ts_nsec(500000000);
            m.set_log_level(llsf_log_msgs::LogMessage::LL_ERROR);
            m.set_component("CLIPS");
            m.set_message("boom");
            m.set_is_exception(true);
          },
          R"(08 80 b0 c8 8e 05  10 80 ca b5 ee 01  18 04  22 05 "CLIPS"  2a 04 "boom"  30 01)"),
  };
  return all;
}

#undef LLSF_POSE_A
#undef LLSF_POSE_B

}  // namespace llsf::msgs_test
