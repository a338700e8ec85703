// SPDX-License-Identifier: MIT
// The planner's own description of the field: size, devices with their footprints and RFID
// zones, the marked areas, extra obstacles; and the named places derived from it.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "llsf/core/geometry.h"

namespace llsf::planner {

using core::OrientedBox;
using core::Pose2D;
using core::Vec2;

/// What a device is for; decides which places it gets.
enum class DeviceRole { kProduction, kRecycling, kTest, kDelivery };

/// One signal/RFID device as the planner sees it. `pose` heading is the facing: the direction
/// in which the reader looks out onto the field.
struct FieldDevice {
  std::string name;  ///< "M1" .. "M10", "R1", "R2", "TST", "D1" .. "D3"
  DeviceRole role = DeviceRole::kProduction;
  Pose2D pose;
  OrientedBox footprint;       ///< the body, an obstacle
  Vec2 rfid_center{0.0, 0.0};  ///< where a puck must lie to be read
};

/// A static obstacle that is not a device (e.g. a board put on the field for a test).
struct NamedBox {
  std::string name;
  OrientedBox box;
};

/// An axis-aligned rectangle [lo, hi] in metres.
struct AreaRect {
  Vec2 lo{0.0, 0.0};
  Vec2 hi{0.0, 0.0};
  Vec2 center() const { return 0.5 * (lo + hi); }
  bool contains(const Vec2& p) const {
    return p.x() >= lo.x() && p.y() >= lo.y() && p.x() <= hi.x() && p.y() <= hi.y();
  }
};

/// The field: walls around [0, width] x [0, height], devices, extra obstacles, marked areas.
/// sim/ builds it from the world's configuration. Copyable value.
struct FieldMap {
  double width_m = 5.6;
  double height_m = 5.6;
  std::vector<FieldDevice> devices;
  std::vector<NamedBox> obstacles;
  AreaRect insertion_area{{0.0, 0.0}, {0.4, 2.3}};
  AreaRect input_storage{{0.0, 2.3}, {0.4, 3.3}};
  AreaRect late_order_area{{0.0, 3.3}, {0.4, 3.9}};
  Vec2 late_order_slot{0.20, 3.60};
  AreaRect delivery_zone{{5.2, 2.3}, {5.6, 3.3}};

  /// The device called `name`, or nullptr.
  const FieldDevice* device(std::string_view name) const;
  /// Throws core::ConfigError naming the field ("field.devices[3].name: duplicate name M4") for
  /// non-positive sizes, empty or duplicate names and obstacles outside the field.
  void validate() const;
};

/// What a named place is for.
enum class PlaceKind {
  kDeviceInput,    ///< facing a device so that a held puck lies in its RFID zone
  kDeviceSide,     ///< facing a production machine beside its RFID zone (consumed pucks)
  kDeviceLook,     ///< facing a device's signal light from a distance (exploration)
  kStoragePickup,  ///< facing the input storage, a held puck at a pick-up spot
  kLateOrderSlot,  ///< facing the late-order insertion slot
  kWaiting,        ///< out of the way, near a contested area
  kUser,           ///< given in the configuration
};

/// A named robot pose on the field. `target` is the point the place is about (the RFID zone
/// centre, the spot of a consumed puck, the light, ...); for waiting points it is the position.
struct Place {
  std::string name;
  PlaceKind kind = PlaceKind::kUser;
  Pose2D pose;
  Vec2 target{0.0, 0.0};
  std::string device;  ///< the device the place belongs to, empty if none
};

}  // namespace llsf::planner
