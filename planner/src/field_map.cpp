// SPDX-License-Identifier: MIT
// FieldMap validation and the derivation of named places (docs/planner.md, "Places").
#include <cmath>
#include <cstdio>
#include <set>

#include "llsf/core/error.h"
#include "places.h"

namespace llsf::planner {

using core::ConfigError;

const FieldDevice* FieldMap::device(std::string_view name) const {
  for (const FieldDevice& d : devices) {
    if (d.name == name) return &d;
  }
  return nullptr;
}

namespace {

std::string xy(const Vec2& p) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f)", p.x(), p.y());
  return buf;
}

void check_box(const std::string& path, const OrientedBox& b, const FieldMap& f) {
  if (!(b.half_extents.x() > 0.0) || !(b.half_extents.y() > 0.0) ||
      !std::isfinite(b.half_extents.x()) || !std::isfinite(b.half_extents.y()))
    throw ConfigError(path + ": box half extents must be > 0");
  for (const Vec2& c : b.corners()) {
    if (!std::isfinite(c.x()) || !std::isfinite(c.y()) || c.x() < -1e-9 || c.y() < -1e-9 ||
        c.x() > f.width_m + 1e-9 || c.y() > f.height_m + 1e-9)
      throw ConfigError(path + ": corner " + xy(c) + " lies outside the field");
  }
}

}  // namespace

void FieldMap::validate() const {
  if (!(width_m > 0.0) || !std::isfinite(width_m)) throw ConfigError("field.width_m: must be > 0");
  if (!(height_m > 0.0) || !std::isfinite(height_m))
    throw ConfigError("field.height_m: must be > 0");
  std::set<std::string> names;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const std::string path = "field.devices[" + std::to_string(i) + "]";
    const FieldDevice& d = devices[i];
    if (d.name.empty()) throw ConfigError(path + ".name: must not be empty");
    if (!names.insert(d.name).second) throw ConfigError(path + ".name: duplicate name " + d.name);
    check_box(path + ".footprint", d.footprint, *this);
  }
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const std::string path = "field.obstacles[" + std::to_string(i) + "]";
    if (obstacles[i].name.empty()) throw ConfigError(path + ".name: must not be empty");
    if (!names.insert(obstacles[i].name).second)
      throw ConfigError(path + ".name: duplicate name " + obstacles[i].name);
    check_box(path + ".box", obstacles[i].box, *this);
  }
}

namespace detail {

namespace {

using core::kPi;
using core::unit;

/// Pose of a robot holding a puck at `spot`, facing along `heading`.
Pose2D holding_at(const Vec2& spot, double heading, double held_offset) {
  const Vec2 c = spot - held_offset * unit(heading);
  return {c.x(), c.y(), core::normalize_angle(heading)};
}

/// The side of an area that opens onto the field: the unit axis direction from the area's
/// centre towards the field centre that dominates.
Vec2 open_side(const AreaRect& area, const FieldMap& f) {
  const Vec2 d = Vec2(0.5 * f.width_m, 0.5 * f.height_m) - area.center();
  if (std::abs(d.x()) >= std::abs(d.y())) return {d.x() >= 0.0 ? 1.0 : -1.0, 0.0};
  return {0.0, d.y() >= 0.0 ? 1.0 : -1.0};
}

/// Distance from the area's centre to its edge along the axis `dir`.
double half_along(const AreaRect& a, const Vec2& dir) {
  return std::abs(dir.x()) > 0.5 ? 0.5 * (a.hi.x() - a.lo.x()) : 0.5 * (a.hi.y() - a.lo.y());
}

/// The free point nearest to `p` on rings of growing radius (1 cm steps, 32 directions,
/// up to 0.5 m), or `p` itself if it is free.
std::optional<Vec2> nearest_free(const StaticMap& map, const Vec2& p) {
  if (map.point_free(p)) return p;
  for (int k = 1; k <= 50; ++k) {
    for (int j = 0; j < 32; ++j) {
      const Vec2 q = p + 0.01 * k * unit(2.0 * kPi * j / 32.0);
      if (map.point_free(q)) return q;
    }
  }
  return std::nullopt;
}

class Builder {
 public:
  explicit Builder(const StaticMap& m) : map_(m) {}

  /// Adds a place that must be free where it is.
  void exact(Place p) {
    if (!map_.point_free(p.pose.position())) {
      int which = 0;
      const double d = map_.signed_distance(p.pose.position(), &which);
      char buf[96];
      std::snprintf(buf, sizeof buf, "%.3f m from %s, the robot needs %.3f m", d,
                    map_.obstacle_name(which).c_str(), map_.radius());
      throw ConfigError("places." + p.name + ": pose " + xy(p.pose.position()) + " is " + buf);
    }
    add(std::move(p));
  }
  /// Adds a place at the nearest free point to its nominal pose.
  void nearest(Place p) {
    const auto q = nearest_free(map_, p.pose.position());
    if (!q)
      throw ConfigError("places." + p.name + ": no free pose within 0.5 m of " +
                        xy(p.pose.position()));
    p.pose.x = q->x();
    p.pose.y = q->y();
    if (p.kind == PlaceKind::kWaiting) p.target = *q;
    add(std::move(p));
  }
  std::vector<Place> take() { return std::move(places_); }

 private:
  void add(Place p) {
    if (!names_.insert(p.name).second) throw ConfigError("places." + p.name + ": duplicate name");
    places_.push_back(std::move(p));
  }
  const StaticMap& map_;
  std::vector<Place> places_;
  std::set<std::string> names_;
};

}  // namespace

std::vector<Place> derive_places(const FieldMap& f, const PlacesConfig& c, const StaticMap& map) {
  Builder b(map);
  const double held = c.held_puck_offset_m;

  // Devices: input (held puck in the RFID zone), side spots (production machines), look.
  for (const FieldDevice& d : f.devices) {
    const double facing = d.pose.theta;
    const double towards = facing + kPi;  // the robot faces the device
    b.exact({d.name + "_input", PlaceKind::kDeviceInput, holding_at(d.rfid_center, towards, held),
             d.rfid_center, d.name});
    if (d.role == DeviceRole::kProduction) {
      // Left/right as seen by the robot facing the device.
      const Vec2 left = unit(towards + 0.5 * kPi);
      const Vec2 l = d.rfid_center + c.side_offset_m * left;
      const Vec2 r = d.rfid_center - c.side_offset_m * left;
      b.exact({d.name + "_left", PlaceKind::kDeviceSide, holding_at(l, towards, held), l, d.name});
      b.exact({d.name + "_right", PlaceKind::kDeviceSide, holding_at(r, towards, held), r, d.name});
    }
    // Look position: nominally look_distance_m out along the facing; if that is not free (a
    // neighbouring machine), the nearest free point on the facing ray within +-0.3 m.
    const Vec2 light = d.pose.position();
    std::optional<Vec2> look;
    for (int k = 0; k <= 30 && !look; ++k) {
      for (int sign : {1, -1}) {
        const double dist = c.look_distance_m + sign * 0.01 * k;
        const Vec2 q = light + dist * unit(facing);
        if (map.point_free(q)) {
          look = q;
          break;
        }
      }
    }
    if (!look) throw ConfigError("places." + d.name + "_look: no free pose on the facing ray");
    b.exact({d.name + "_look", PlaceKind::kDeviceLook,
             Pose2D{look->x(), look->y(), core::normalize_angle(towards)}, light, d.name});
  }

  // Input storage pick-ups: spots along the storage, storage_pickup_depth_m in from its open
  // side; the robot faces into the storage.
  {
    const AreaRect& s = f.input_storage;
    const Vec2 out = open_side(s, f);
    const Vec2 along(-out.y(), out.x());
    const double half_len = half_along(s, along);
    const Vec2 front = s.center() + (half_along(s, out) - c.storage_pickup_depth_m) * out;
    const double towards = std::atan2(-out.y(), -out.x());
    for (int i = 0; i < c.storage_pickups; ++i) {
      const double t = -half_len + (i + 0.5) * (2.0 * half_len / c.storage_pickups);
      const Vec2 spot = front + t * along;
      b.exact({"INS_" + std::to_string(i + 1), PlaceKind::kStoragePickup,
               holding_at(spot, towards, held), spot, ""});
    }
  }

  // Late-order slot: a held puck on the slot, facing in from the open side.
  {
    const Vec2 out = open_side(f.late_order_area, f);
    const double towards = std::atan2(-out.y(), -out.x());
    b.exact({"LATE_ORDER", PlaceKind::kLateOrderSlot, holding_at(f.late_order_slot, towards, held),
             f.late_order_slot, ""});
  }

  // Waiting points off the storage and the delivery zone, facing the field.
  for (const auto& [name, area] :
       {std::pair<const char*, AreaRect>{"WAIT_INS", f.input_storage},
        std::pair<const char*, AreaRect>{"WAIT_DELIVERY", f.delivery_zone}}) {
    const Vec2 out = open_side(area, f);
    const Vec2 p = area.center() + (half_along(area, out) + c.wait_distance_m) * out +
                   c.wait_lateral_m * Vec2(0.0, 1.0);
    b.nearest(
        {name, PlaceKind::kWaiting, Pose2D{p.x(), p.y(), std::atan2(out.y(), out.x())}, p, ""});
  }

  for (const UserPlace& u : c.extra) {
    b.exact({u.name, PlaceKind::kUser, u.pose, u.pose.position(), ""});
  }
  return b.take();
}

}  // namespace detail
}  // namespace llsf::planner
