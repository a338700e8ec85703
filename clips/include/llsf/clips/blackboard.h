// SPDX-License-Identifier: MIT
// Blackboard: the robot's interfaces as a Fawkes-style agent's blackboard feature reads and
// writes them (docs/fawkes.md, "The blackboard"). The host writes some itself (the pose, and
// what AgentHost::write_interface is given); the others come from a Blackboard the caller plugs
// in (sim: the skill engine's interface objects, which llsfsim's sensors and actuators fill).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "llsf/clips/value.h"
#include "llsf/core/sim_time.h"

namespace llsf::clips {

/// Field name and value (a multifield for an array field; enums and booleans as symbols).
using InterfaceFields = std::vector<std::pair<std::string, Value>>;

/// The data of one interface as a reader sees them.
struct InterfaceReading {
  bool has_writer = false;    ///< something writes the interface (Fawkes' has_writer())
  bool robot_writer = false;  ///< llsfsim's sensors or actuators write it (no other writer)
  std::optional<core::SimTime> written;  ///< when it was last written; none: never
  InterfaceFields fields;
};

/// The robot's blackboard beyond the host's own interfaces. Borrowed by AgentIo.
class Blackboard {
 public:
  virtual ~Blackboard() = default;
  /// Reads interface (type, id) now; false with `error` set for a type it does not offer.
  virtual bool read(std::string_view type, std::string_view id, InterfaceReading& out,
                    std::string& error) = 0;
  /// A number that changes whenever an interface without a robot writer may have changed (a
  /// write or a message); the host reads such an interface again only then. 0: unknown (the
  /// host reads every opened interface at every cycle).
  virtual std::int64_t version() { return 0; }
  /// Writes fields of interface (type, id) (the agent is its writer); "" or why not.
  virtual std::string write(std::string_view type, std::string_view id,
                            const InterfaceFields& fields) = 0;
  /// Sends `message` ("CartesianGotoMessage") with `fields` to the interface's writer, which
  /// handles it at once; the message id, or 0 with `error` set.
  virtual std::int64_t send(std::string_view type, std::string_view id, std::string_view message,
                            const InterfaceFields& fields, std::string& error) = 0;
};

}  // namespace llsf::clips
