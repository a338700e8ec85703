// SPDX-License-Identifier: MIT
// A random-play driver: a stand-in for the world and a team of robots that moves pucks between
// the input storage, the robots and the devices' RFID zones, mostly by the rules (inputs a
// machine needs, consumed pucks to a recycler, products to the active gate) and sometimes at
// random (wrong inputs, junk, inactive gates). It carries out the referee actions and sends
// exploration reports. Used by the seed-sweep tests and the refbox benchmark.
#pragma once

#include <vector>

#include "llsf/core/rng.h"
#include "llsf/refbox/io.h"
#include "llsf/refbox/refbox.h"

namespace llsf::refbox {

/// Where the driver's world keeps a puck.
struct PlayPuckPlace {
  enum class Kind : std::uint8_t { kStorage, kSlot, kCarried, kZone, kSpace, kGone };
  Kind kind = Kind::kStorage;
  DeviceId device;  ///< for kZone (under the reader) and kSpace (beside it, in the machine space)
};

/// Drives a Refbox with random but mostly sensible puck moves. Copyable; deterministic in the
/// stream it is given.
class RandomPlay {
 public:
  /// `robots` robots act every `min_pause_s`..`max_pause_s` seconds each; `rule_bias` is the
  /// probability that a move follows the rules.
  RandomPlay(core::RandomStream stream, int robots = 3, double rule_bias = 0.8,
             double min_pause_s = 1.0, double max_pause_s = 4.0);

  /// Produces this step's inputs from the refbox state after its previous step (`last` = that
  /// step's outputs): RFID events into `rfid`, reports into `reports` (both cleared first).
  void act(const Refbox& rb, const StepOutput& last, SimTime now, std::vector<RfidEvent>& rfid,
           std::vector<MachineReport>& reports);
  /// True while a puck lies in the late-order insertion slot.
  bool insertion_slot_occupied() const;
  /// Where puck `id` is (kGone for unknown ids).
  PlayPuckPlace place_of(PuckId id) const;

 private:
  struct RobotPlan {
    SimTime next_action;
    PuckId carried;
  };
  void pick_up(const Refbox& rb, RobotPlan& r, std::vector<RfidEvent>& rfid);
  void put_down(const Refbox& rb, RobotPlan& r, std::vector<RfidEvent>& rfid);
  DeviceId target_for(const Refbox& rb, PuckState s);
  PlayPuckPlace& at(PuckId id);

  core::RandomStream rng_;
  double rule_bias_;
  double min_pause_s_;
  double max_pause_s_;
  std::vector<RobotPlan> robots_;
  std::vector<PlayPuckPlace> places_;  ///< indexed by puck id
  std::vector<PuckId> candidates_;     ///< scratch
  SimTime next_report_;
};

}  // namespace llsf::refbox
