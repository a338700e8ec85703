// SPDX-License-Identifier: MIT
// Benchmark of the referee box: the cost of one Refbox::step at 100 Hz during PRODUCTION with
// typical traffic (three robots moving pucks under machines by the random-play driver, beacons
// of three robots at 1 Hz). The inputs of a whole production phase are recorded once and then
// replayed into fresh refboxes, so that only the refbox is timed.
#include <string>
#include <vector>

#include "harness.h"
#include "llsf/refbox/random_play.h"
#include "llsf/refbox/refbox.h"

using namespace llsf;
using namespace llsf::refbox;

namespace {

constexpr SimTime kStep = SimTime::from_ms(10);
constexpr int kRepeats = 5;

/// The inputs of every step of one production phase, flattened.
struct Recording {
  std::vector<RfidEvent> rfid;
  std::vector<Beacon> beacons;
  std::vector<MachineReport> no_reports;
  std::vector<int> rfid_begin;    ///< per step, index into rfid (plus one end entry)
  std::vector<int> beacon_begin;  ///< per step, index into beacons (plus one end entry)
  std::vector<char> slot;         ///< per step: insertion slot occupied
};

RefboxConfig bench_config() {
  RefboxConfig c;
  c.team = "Carologistics";
  return c;
}

/// The two commands that jump into PRODUCTION and start the clock.
std::vector<Command> start_commands() {
  std::vector<Command> cmds;
  cmds.emplace_back(std::in_place_type<command::SetGamePhase>,
                    command::SetGamePhase{GamePhase::kProduction});
  cmds.emplace_back(std::in_place_type<command::SetGameState>,
                    command::SetGameState{GameState::kRunning});
  return cmds;
}

Recording record(std::uint64_t seed) {
  const core::Rng rng(seed);
  Refbox rb(bench_config(), rng);
  RandomPlay play(rng.stream("bench/play"));
  Recording rec;
  const std::vector<Command> start = start_commands();
  StepInput in;
  in.commands = start;
  SimTime now;
  const StepOutput* out = &rb.step(now, in);
  std::vector<RfidEvent> rfid;
  std::vector<MachineReport> reports;
  std::vector<Beacon> beacons;
  for (int step = 1; rb.phase() == GamePhase::kProduction; ++step) {
    now += kStep;
    play.act(rb, *out, now, rfid, reports);
    beacons.clear();
    if (step % 100 < 3) {  // three robots, one beacon each per second
      const int n = step % 100 + 1;
      Beacon b;
      b.time = now;
      b.team = "Carologistics";
      b.peer_name = "R-" + std::to_string(n);
      b.number = n;
      b.host = "172.26.1." + std::to_string(n);
      b.port = 4444;
      b.pose = core::Pose2D{1.0 * n, 2.0, 0.0};
      beacons.push_back(b);
    }
    rec.rfid_begin.push_back(static_cast<int>(rec.rfid.size()));
    rec.beacon_begin.push_back(static_cast<int>(rec.beacons.size()));
    rec.slot.push_back(play.insertion_slot_occupied());
    rec.rfid.insert(rec.rfid.end(), rfid.begin(), rfid.end());
    rec.beacons.insert(rec.beacons.end(), beacons.begin(), beacons.end());
    in = StepInput{};
    in.rfid = rfid;
    in.beacons = beacons;
    in.insertion_slot_occupied = rec.slot.back();
    out = &rb.step(now, in);
  }
  rec.rfid_begin.push_back(static_cast<int>(rec.rfid.size()));
  rec.beacon_begin.push_back(static_cast<int>(rec.beacons.size()));
  return rec;
}

/// CPU microseconds per step when replaying `rec` into a fresh refbox; also returns the points.
double replay_us_per_step(const Recording& rec, std::uint64_t seed, int* points) {
  Refbox rb(bench_config(), core::Rng(seed));
  const std::vector<Command> start = start_commands();
  StepInput in;
  in.commands = start;
  SimTime now;
  rb.step(now, in);
  const int steps = static_cast<int>(rec.slot.size());
  const double t0 = bench::cpu_seconds();
  for (int i = 0; i < steps; ++i) {
    now += kStep;
    StepInput s;
    s.rfid = std::span<const RfidEvent>(rec.rfid.data() + rec.rfid_begin[i],
                                        rec.rfid.data() + rec.rfid_begin[i + 1]);
    s.beacons = std::span<const Beacon>(rec.beacons.data() + rec.beacon_begin[i],
                                        rec.beacons.data() + rec.beacon_begin[i + 1]);
    s.insertion_slot_occupied = rec.slot[i] != 0;
    rb.step(now, s);
  }
  const double us = (bench::cpu_seconds() - t0) * 1e6 / steps;
  *points = rb.points();
  return us;
}

}  // namespace

LLSF_BENCH(refbox_step,
           "Refbox::step at 100 Hz over a whole PRODUCTION phase, 3 robots moving pucks, beacons") {
  constexpr std::uint64_t kSeed = 7;
  const Recording rec = record(kSeed);
  int points = 0;
  const double us =
      bench::median_of(kRepeats, [&] { return replay_us_per_step(rec, kSeed, &points); });
  const double steps = static_cast<double>(rec.slot.size());
  bench::report("refbox_step", "us_per_step", us, "us");
  bench::report("refbox_step", "rfid_events_per_s", rec.rfid.size() / (steps / 100.0), "1/s");
  bench::report("refbox_step", "game_points", points, "points");
}

namespace {

/// CPU microseconds per step of a whole WHACK_A_MOLE_CHALLENGE at 100 Hz with three robots'
/// camera poses every step; one robot reaches the mole every 5 s. Also returns the points.
double whack_a_mole_us_per_step(std::uint64_t seed, int* points) {
  const RefboxConfig cfg = bench_config();
  Refbox rb(cfg, core::Rng(seed));
  std::vector<Command> start;
  start.emplace_back(std::in_place_type<command::SetGamePhase>,
                     command::SetGamePhase{GamePhase::kWhackAMoleChallenge});
  start.emplace_back(std::in_place_type<command::SetGameState>,
                     command::SetGameState{GameState::kRunning});
  StepInput in;
  in.commands = start;
  SimTime now;
  rb.step(now, in);
  std::vector<RobotPose> poses = {{1, {0.8, 0.8, 0.0}}, {2, {0.8, 4.5, 0.0}}, {3, {4.6, 4.6, 0.0}}};
  int steps = 0;
  const double t0 = bench::cpu_seconds();
  while (rb.phase() == GamePhase::kWhackAMoleChallenge) {
    now += kStep;
    ++steps;
    poses[0].pose = core::Pose2D{0.8, 0.8, 0.0};
    if (steps % 500 == 0 && rb.mole()) poses[0].pose = cfg.device_poses[rb.mole()->value()];
    StepInput s;
    s.robot_poses = poses;
    rb.step(now, s);
  }
  const double us = (bench::cpu_seconds() - t0) * 1e6 / steps;
  *points = rb.points();
  return us;
}

}  // namespace

LLSF_BENCH(refbox_step_whack_a_mole,
           "Refbox::step at 100 Hz over a whole WHACK_A_MOLE_CHALLENGE, 3 robots' vision poses") {
  int points = 0;
  const double us =
      bench::median_of(kRepeats, [&] { return whack_a_mole_us_per_step(7, &points); });
  bench::report("refbox_step_whack_a_mole", "us_per_step", us, "us");
  bench::report("refbox_step_whack_a_mole", "game_points", points, "points");
}
