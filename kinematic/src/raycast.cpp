// SPDX-License-Identifier: MIT
// Ray casting by angular rasterisation: each visible face or circle is projected onto the beam
// fan once, and only the beams inside its angular shadow are intersected with it.
#include "raycast.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "llsf/core/assert.h"

namespace llsf::kinematic {

namespace {

constexpr double kTwoPi = 2.0 * core::kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Slack added to both ends of a shadow interval so that a beam exactly through an endpoint is
/// still tested; the exact intersection test below then decides.
constexpr double kAngleSlack = 1e-9;
/// Slack on the segment parameter so that a beam exactly through a corner shared by two visible
/// faces hits at least one of them despite rounding.
constexpr double kEdgeSlack = 1e-10;
/// Slack on a box's bounding circle when a single ray is culled against it (RayCaster::cast).
constexpr double kCullSlack = 1e-6;

/// Per-scan state shared by the face and circle rasterisers. Geometry is taken relative to the
/// origin and rotated by -angle0, so that beam i has direction (cos_[i], sin_[i]).
class Rasterizer {
 public:
  Rasterizer(const Vec2& origin, double angle0_rad, double increment_rad, int n, double max_range_m,
             const double* cos_table, const double* sin_table, float* ranges_out)
      : ox_(origin.x()),
        oy_(origin.y()),
        c0_(std::cos(angle0_rad)),
        s0_(std::sin(angle0_rad)),
        inv_increment_(1.0 / increment_rad),
        last_(n - 1),
        max_range_(max_range_m),
        cos_(cos_table),
        sin_(sin_table),
        out_(ranges_out) {}

  /// Intersects the face a -> a + e with the beams of its shadow, if its visible side faces the
  /// origin and some part of it is within range.
  void face(double ax, double ay, double ex, double ey, double inv_len2) const {
    const double wx = ax - ox_, wy = ay - oy_;
    const double num = wx * ey - wy * ex;  // cross(w, e): < 0 iff the origin sees the front
    if (!(num < 0.0)) return;
    // Nearest point of the face: skip faces entirely out of range.
    const double k = std::clamp(-(wx * ex + wy * ey) * inv_len2, 0.0, 1.0);
    const double qx = wx + k * ex, qy = wy + k * ey;
    if (qx * qx + qy * qy > max_range_ * max_range_) return;

    // Into the beam frame.
    const double rax = c0_ * wx + s0_ * wy, ray = c0_ * wy - s0_ * wx;
    const double rex = c0_ * ex + s0_ * ey, rey = c0_ * ey - s0_ * ex;
    // Seen from the origin the face runs clockwise from a to b, so its shadow is [angle(b),
    // angle(a)] counter-clockwise, narrower than pi.
    const double angle_b = std::atan2(ray + rey, rax + rex);
    const double angle_a = std::atan2(ray, rax);
    double width = angle_a - angle_b;
    if (width < 0.0) width += kTwoPi;
    const double lo = angle_b < 0.0 ? angle_b + kTwoPi : angle_b;

    for_beams(lo, lo + width, [&](int i) {
      const double c = cos_[i], s = sin_[i];
      const double denom = c * rey - s * rex;  // cross(dir, e)
      if (!(denom < 0.0)) return;
      const double inv = 1.0 / denom;
      const double t = num * inv;
      const double u = (rax * s - ray * c) * inv;  // cross(w, dir) / cross(dir, e)
      if (u >= -kEdgeSlack && u <= 1.0 + kEdgeSlack && t <= max_range_) {
        out_[i] = std::min(out_[i], static_cast<float>(t));
      }
    });
  }

  /// Intersects a circle not containing the origin with the beams of its shadow.
  void circle(const Circle& circle) const {
    const double r = circle.radius;
    if (!(r > 0.0)) return;
    const double mx = circle.center.x() - ox_, my = circle.center.y() - oy_;
    const double d2 = mx * mx + my * my;
    const double c = d2 - r * r;
    if (!(c > 0.0)) return;  // the origin is inside or on the circle
    const double d = std::sqrt(d2);
    if (d - r > max_range_) return;

    const double rmx = c0_ * mx + s0_ * my, rmy = c0_ * my - s0_ * mx;
    const double half = std::asin(std::min(1.0, r / d));
    double lo = std::atan2(rmy, rmx) - half;
    if (lo < 0.0) lo += kTwoPi;

    for_beams(lo, lo + 2.0 * half, [&](int i) {
      const double p = rmx * cos_[i] + rmy * sin_[i];  // centre projected on the beam
      const double disc = p * p - c;
      if (disc < 0.0) return;
      const double t = p - std::sqrt(disc);
      if (t >= 0.0 && t <= max_range_) out_[i] = std::min(out_[i], static_cast<float>(t));
    });
  }

 private:
  /// Calls f(i) for every beam i whose relative angle i * increment lies in [lo, hi] modulo 2 pi
  /// (widened by kAngleSlack); lo in [0, 2 pi], hi - lo < 2 pi.
  template <class F>
  void for_beams(double lo, double hi, F&& f) const {
    // The interval may wrap past 2 pi onto the first beams; the beams may wrap past 2 pi too.
    double shift = hi + kAngleSlack >= kTwoPi ? -kTwoPi : 0.0;
    for (;; shift += kTwoPi) {
      const double f0 = (lo + shift - kAngleSlack) * inv_increment_;
      if (!(f0 <= last_)) break;  // also ends on NaN
      const double f1 = (hi + shift + kAngleSlack) * inv_increment_;
      if (f1 < 0.0) continue;
      int i0 = 0;
      if (f0 > 0.0) {  // ceil without a libm call
        i0 = static_cast<int>(f0);
        if (i0 < f0) ++i0;
      }
      const int i1 = f1 >= last_ ? last_ : static_cast<int>(f1);
      for (int i = i0; i <= i1; ++i) f(i);
    }
  }

  double ox_, oy_;
  double c0_, s0_;  // rotation by angle0
  double inv_increment_;
  int last_;
  double max_range_;
  const double* cos_;
  const double* sin_;
  float* out_;
};

}  // namespace

RayCaster::RayCaster(const WorldConfig& config) {
  // The field boundary, clockwise so that the interior is on each face's visible side.
  const double w = config.field.width_m, h = config.field.height_m;
  const Vec2 corners[4] = {{0.0, 0.0}, {0.0, h}, {w, h}, {w, 0.0}};
  segments_.reserve(4 + 4 * kDeviceCount);
  for (int k = 0; k < 4; ++k) add_segment(corners[k], corners[(k + 1) % 4], HitKind::kWall, -1);
  wall_count_ = static_cast<int>(segments_.size());

  // Device boxes: corners() runs counter-clockwise, so the outside is on the visible side.
  groups_.reserve(kDeviceCount);
  for (int d = 0; d < kDeviceCount; ++d) {
    const core::OrientedBox box = config.devices[d].footprint();
    const auto c = box.corners();
    const int first = static_cast<int>(segments_.size());
    for (int k = 0; k < 4; ++k) add_segment(c[k], c[(k + 1) % 4], HitKind::kDevice, d);
    const int count = static_cast<int>(segments_.size()) - first;
    if (count > 0) {
      groups_.push_back({box.pose.x, box.pose.y, box.half_extents.norm(), first, count});
    }
  }
  // Extra obstacles: boxes seen like walls.
  for (const ObstacleConfig& o : config.obstacles) {
    const core::OrientedBox box = o.footprint();
    const auto c = box.corners();
    const int first = static_cast<int>(segments_.size());
    for (int k = 0; k < 4; ++k) add_segment(c[k], c[(k + 1) % 4], HitKind::kWall, -1);
    const int count = static_cast<int>(segments_.size()) - first;
    if (count > 0) {
      groups_.push_back({box.pose.x, box.pose.y, box.half_extents.norm(), first, count});
    }
  }
}

void RayCaster::add_segment(const Vec2& a, const Vec2& b, HitKind kind, int index) {
  const Vec2 e = b - a;
  const double len2 = e.squaredNorm();
  if (!(len2 > 0.0)) return;  // a degenerate face is invisible
  segments_.push_back({a.x(), a.y(), e.x(), e.y(), 1.0 / len2, kind, index});
}

namespace {

/// The nearest hit of one ray so far: faces and circles offered in a fixed order, the first of
/// equally near ones kept.
struct RayProbe {
  Vec2 origin;
  double dx, dy;  ///< the ray's direction (unit)
  double best = kInf;
  HitKind kind = HitKind::kNone;
  int index = -1;

  // A face a -> a + e, seen from its visible side.
  void face(double ax, double ay, double ex, double ey, HitKind face_kind, int face_index) {
    const double wx = ax - origin.x(), wy = ay - origin.y();
    const double num = wx * ey - wy * ex;
    const double denom = dx * ey - dy * ex;
    if (!(num < 0.0) || !(denom < 0.0)) return;
    const double t = num / denom;
    const double u = (wx * dy - wy * dx) / denom;
    if (u >= -kEdgeSlack && u <= 1.0 + kEdgeSlack && t < best) {
      best = t;
      kind = face_kind;
      index = face_index;
    }
  }
  // Circles not containing the origin.
  void circles(std::span<const Circle> cs, HitKind circle_kind) {
    for (const Circle& c : cs) {
      const double mx = c.center.x() - origin.x(), my = c.center.y() - origin.y();
      const double cc = mx * mx + my * my - c.radius * c.radius;
      if (!(c.radius > 0.0) || !(cc > 0.0)) continue;
      const double p = mx * dx + my * dy;
      const double disc = p * p - cc;
      if (disc < 0.0) continue;
      const double t = p - std::sqrt(disc);
      if (t >= 0.0 && t < best) {
        best = t;
        kind = circle_kind;
        index = c.index;
      }
    }
  }
  RayHit result(double max_range_m) const {
    if (!(best <= max_range_m)) return {max_range_m, HitKind::kNone, -1};
    return {best, kind, index};
  }
};

}  // namespace

void RayCaster::faces_near(const Vec2& center, double reach_m, std::vector<int>& faces) const {
  faces.clear();
  const double reach = reach_m + kCullSlack;
  for (int k = 0; k < wall_count_; ++k) {
    const Segment& s = segments_[k];
    // The wall's point nearest to the centre.
    const double wx = center.x() - s.ax, wy = center.y() - s.ay;
    const double u = std::clamp((wx * s.ex + wy * s.ey) * s.inv_len2, 0.0, 1.0);
    const double qx = wx - u * s.ex, qy = wy - u * s.ey;
    if (qx * qx + qy * qy <= reach * reach) faces.push_back(k);
  }
  // A box's faces when its bounding circle comes within reach (groups_ are in segment order).
  for (const DeviceGroup& g : groups_) {
    const double gx = g.cx - center.x(), gy = g.cy - center.y();
    const double r = reach + g.radius;
    if (gx * gx + gy * gy > r * r) continue;
    for (int k = g.first; k < g.first + g.count; ++k) faces.push_back(k);
  }
}

RayHit RayCaster::cast_among(const Vec2& origin, double dir_x, double dir_y, double max_range_m,
                             std::span<const int> faces, std::span<const Circle> robots,
                             std::span<const Circle> pucks) const {
  RayProbe ray{origin, dir_x, dir_y};
  for (const int k : faces) {
    const Segment& s = segments_[static_cast<std::size_t>(k)];
    ray.face(s.ax, s.ay, s.ex, s.ey, s.kind, s.index);
  }
  ray.circles(robots, HitKind::kRobot);
  ray.circles(pucks, HitKind::kPuck);
  return ray.result(max_range_m);
}

RayHit RayCaster::cast(const Vec2& origin, double angle_rad, double max_range_m,
                       std::span<const Circle> robots, std::span<const Circle> pucks) const {
  const double dx = std::cos(angle_rad), dy = std::sin(angle_rad);
  RayProbe ray{origin, dx, dy};
  auto check_face = [&](const Segment& s) { ray.face(s.ax, s.ay, s.ex, s.ey, s.kind, s.index); };
  for (int k = 0; k < wall_count_; ++k) check_face(segments_[k]);
  // A box's faces only when the ray, up to max_range_m, passes within its bounding circle
  // (widened by kCullSlack, far more than the faces' kEdgeSlack can reach past a corner): the
  // faces of a box the ray cannot reach would give no hit, or one beyond max_range_m, which the
  // result ignores (segments are in groups_ order, so the hits compared are the same).
  for (const DeviceGroup& g : groups_) {
    const double gx = g.cx - origin.x(), gy = g.cy - origin.y();
    const double r = g.radius + kCullSlack;
    const double along = gx * dx + gy * dy;  // the circle's centre projected on the ray
    const double across = gx * dy - gy * dx;
    if (across * across > r * r) continue;                // the line misses the circle
    if (along < -r || along > max_range_m + r) continue;  // behind the origin, or out of range
    for (int k = g.first; k < g.first + g.count; ++k) check_face(segments_[k]);
  }
  ray.circles(robots, HitKind::kRobot);
  ray.circles(pucks, HitKind::kPuck);
  return ray.result(max_range_m);
}

void RayCaster::scan(const Vec2& origin, double angle0_rad, double increment_rad, int n,
                     double max_range_m, std::span<const Circle> circles, float* ranges_out) const {
  thread_local ScanScratch scratch;
  scan(origin, angle0_rad, increment_rad, n, max_range_m, circles, ranges_out, scratch);
}

void RayCaster::scan(const Vec2& origin, double angle0_rad, double increment_rad, int n,
                     double max_range_m, std::span<const Circle> circles, float* ranges_out,
                     ScanScratch& scratch) const {
  LLSF_DEMAND(n >= 0);
  if (n == 0) return;
  LLSF_DEMAND(ranges_out != nullptr);
  LLSF_DEMAND(std::isfinite(origin.x()) && std::isfinite(origin.y()) && std::isfinite(angle0_rad));
  LLSF_DEMAND_MSG(n == 1 || (increment_rad > 0.0 && std::isfinite(increment_rad)),
                  "RayCaster::scan needs a positive increment");
  std::fill_n(ranges_out, n, std::numeric_limits<float>::infinity());
  if (!(max_range_m > 0.0)) return;
  // A single beam needs no increment; any positive one places it at angle0.
  const double increment = n == 1 ? kTwoPi : increment_rad;

  // The beam directions relative to angle0, computed once per (n, increment).
  if (scratch.beams_ != n || scratch.increment_rad_ != increment) {
    scratch.cos_.resize(n);
    scratch.sin_.resize(n);
    for (int i = 0; i < n; ++i) {
      scratch.cos_[i] = std::cos(i * increment);
      scratch.sin_[i] = std::sin(i * increment);
    }
    scratch.beams_ = n;
    scratch.increment_rad_ = increment;
  }

  const Rasterizer raster(origin, angle0_rad, increment, n, max_range_m, scratch.cos_.data(),
                          scratch.sin_.data(), ranges_out);

  // Walls, then device boxes not entirely out of range, then circles.
  for (int k = 0; k < wall_count_; ++k) {
    const Segment& s = segments_[k];
    raster.face(s.ax, s.ay, s.ex, s.ey, s.inv_len2);
  }
  for (const DeviceGroup& g : groups_) {
    const double gx = g.cx - origin.x(), gy = g.cy - origin.y();
    const double reach = max_range_m + g.radius;
    if (gx * gx + gy * gy > reach * reach) continue;
    for (int k = g.first; k < g.first + g.count; ++k) {
      const Segment& s = segments_[k];
      raster.face(s.ax, s.ay, s.ex, s.ey, s.inv_len2);
    }
  }
  for (const Circle& c : circles) raster.circle(c);
}

}  // namespace llsf::kinematic
