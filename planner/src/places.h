// SPDX-License-Identifier: MIT
// Deriving the named places from the device poses and the marked areas.
#pragma once

#include <vector>

#include "llsf/planner/config.h"
#include "static_map.h"

namespace llsf::planner::detail {

/// Every derived place plus the configured ones, in a fixed order (devices in field order, then
/// storage, late-order slot, waiting points, user places). Throws core::ConfigError naming the
/// place if one is not free in `map` or names clash.
std::vector<Place> derive_places(const FieldMap& field, const PlacesConfig& config,
                                 const StaticMap& map);

}  // namespace llsf::planner::detail
