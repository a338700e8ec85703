// SPDX-License-Identifier: MIT
#include <doctest/doctest.h>

#include "llsf/kinematic/world_config.h"

using namespace llsf::kinematic;

TEST_CASE("device names and kinds") {
  CHECK(device_by_name("M1") == DeviceId(0));
  CHECK(device_by_name("M10") == DeviceId(9));
  CHECK(device_by_name("TST") == DeviceId(12));
  CHECK(device_by_name("D3") == DeviceId(15));
  CHECK_FALSE(device_by_name("M11"));
  CHECK_FALSE(device_by_name("m1"));
  CHECK(device_kind(DeviceId(3)) == DeviceKind::kProduction);
  CHECK(device_kind(DeviceId(10)) == DeviceKind::kRecycling);
  CHECK(device_kind(DeviceId(12)) == DeviceKind::kTest);
  CHECK(device_kind(DeviceId(14)) == DeviceKind::kDelivery);
  CHECK(device_name(DeviceId(11)) == "R2");
}

TEST_CASE("device geometry follows the facing") {
  DeviceConfig d;
  d.pose = {1.0, 1.0, llsf::core::kPi / 2};
  d.body_depth_m = 0.2;
  d.body_width_m = 0.3;
  d.body_offset_m = -0.1;
  d.rfid_offset_m = 0.14;
  const auto fp = d.footprint();
  CHECK(fp.pose.x == doctest::Approx(1.0));
  CHECK(fp.pose.y == doctest::Approx(0.9));
  CHECK(d.rfid_center().y() == doctest::Approx(1.14));
  CHECK(fp.contains({1.14, 0.9}));  // width runs along x when facing +y
  CHECK_FALSE(fp.contains({1.0, 1.05}));
}
