// SPDX-License-Identifier: MIT
// Typed ids: a RobotId cannot be passed where a PuckId is expected.
#pragma once

#include <compare>
#include <cstddef>
#include <cstdint>
#include <functional>

namespace llsf::core {

/// A strongly typed integer id; Tag only distinguishes the types. Default-constructed = invalid.
template <class Tag>
class Id {
 public:
  constexpr Id() = default;
  constexpr explicit Id(std::int32_t value) : value_(value) {}
  constexpr std::int32_t value() const { return value_; }
  constexpr bool valid() const { return value_ >= 0; }
  friend constexpr auto operator<=>(Id, Id) = default;

 private:
  std::int32_t value_ = -1;
};

struct RobotTag {};
struct PuckTag {};
struct DeviceTag {};
struct OrderTag {};

/// A robot in the world (index into the world's robot list).
using RobotId = Id<RobotTag>;
/// A puck; its value is also the puck's RFID tag id.
using PuckId = Id<PuckTag>;
/// One of the 16 signal/RFID devices (M1..M10, R1, R2, TST, D1..D3), in that order.
using DeviceId = Id<DeviceTag>;
/// An order of the production plan.
using OrderId = Id<OrderTag>;

}  // namespace llsf::core

template <class Tag>
struct std::hash<llsf::core::Id<Tag>> {
  std::size_t operator()(llsf::core::Id<Tag> id) const noexcept {
    return std::hash<std::int32_t>()(id.value());
  }
};
