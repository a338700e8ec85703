// SPDX-License-Identifier: MIT
// Exact distance queries against the static map with FCL (broad phase + narrow phase). Used off
// the hot path: clearance reports, error messages and place derivation; the per-check hot path
// is StaticMap's hand-written test (~10x cheaper, measured-limits.md §2b).
#pragma once

#include <memory>

#include "static_map.h"

namespace llsf::planner::detail {

class FclDistance {
 public:
  explicit FclDistance(const StaticMap& map);
  ~FclDistance();
  FclDistance(const FclDistance&) = delete;
  FclDistance& operator=(const FclDistance&) = delete;

  /// Distance from `p` to the nearest wall or box, 0 if `p` lies inside one; `which` as
  /// StaticMap::signed_distance().
  double distance(const Vec2& p, int* which) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace llsf::planner::detail
