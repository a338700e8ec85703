// SPDX-License-Identifier: MIT
// Device names, kinds and per-device geometry.
#include "llsf/core/assert.h"
#include "llsf/kinematic/world_config.h"

namespace llsf::kinematic {

std::optional<DeviceId> device_by_name(std::string_view name) {
  for (int i = 0; i < kDeviceCount; ++i) {
    if (kDeviceNames[i] == name) return DeviceId(i);
  }
  return std::nullopt;
}

DeviceKind device_kind(DeviceId id) {
  LLSF_DEMAND(id.valid() && id.value() < kDeviceCount);
  const int i = id.value();
  if (i < 10) return DeviceKind::kProduction;
  if (i < 12) return DeviceKind::kRecycling;
  if (i == 12) return DeviceKind::kTest;
  return DeviceKind::kDelivery;
}

std::string_view device_name(DeviceId id) {
  LLSF_DEMAND(id.valid() && id.value() < kDeviceCount);
  return kDeviceNames[id.value()];
}

core::OrientedBox DeviceConfig::footprint() const {
  const Vec2 c = pose.position() + body_offset_m * core::unit(pose.theta);
  return core::OrientedBox{Pose2D{c.x(), c.y(), pose.theta},
                           Vec2(0.5 * body_depth_m, 0.5 * body_width_m)};
}

Vec2 DeviceConfig::rfid_center() const {
  return pose.position() + rfid_offset_m * core::unit(pose.theta);
}

}  // namespace llsf::kinematic
