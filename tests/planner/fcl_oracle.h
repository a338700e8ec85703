// SPDX-License-Identifier: MIT
// FCL 0.7 as an independent geometry oracle for the planner's hand-written checks (tests only;
// the library does not link FCL, docs/planner.md "FCL"). Walls and boxes of a StaticMap become
// FCL boxes in a dynamic AABB tree, a point a small sphere, a segment a thin capsule, another
// robot a cylinder; every shape is centred on z = 0, so every distance is the planar one.
#pragma once

#include <memory>

#include "static_map.h"

namespace llsf::test {

using planner::Vec2;

class FclOracle {
 public:
  /// The walls around the field and the boxes of `map` (borrowed only during construction).
  explicit FclOracle(const planner::detail::StaticMap& map);
  ~FclOracle();
  FclOracle(const FclOracle&) = delete;
  FclOracle& operator=(const FclOracle&) = delete;

  /// Distance from `p` to the nearest wall or box, 0 if `p` lies inside one; `which` as
  /// StaticMap::signed_distance().
  double distance(const Vec2& p, int* which = nullptr) const;
  /// Distance from the segment [a, b] to the nearest wall or box, 0 if it touches one: the
  /// clearance of a robot's disc swept along it (the robot's footprint along a path segment).
  double segment_distance(const Vec2& a, const Vec2& b, int* which = nullptr) const;
  /// Distance from the segment [a, b] to a disc at `c` of radius `r` (another robot).
  static double segment_disc_distance(const Vec2& a, const Vec2& b, const Vec2& c, double r);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::test
