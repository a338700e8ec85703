// SPDX-License-Identifier: MIT
// 2D poses and geometry helpers (Eigen). SI units: metres and radians, counter-clockwise from +x.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

namespace llsf::core {

using Vec2 = Eigen::Vector2d;

inline constexpr double kPi = std::numbers::pi;

/// Wraps an angle to (-pi, pi].
double normalize_angle(double rad);
/// The signed smallest rotation from `from` to `to`, in (-pi, pi].
double angle_diff(double to, double from);
/// atan2(y, x) within kRoughAtan2Error, for what only needs a range of directions (widened by
/// that much) and decides exactly afterwards; a fraction of std::atan2's instructions.
double rough_atan2(double y, double x);
/// rough_atan2's largest error, radians (0.0038: Rajan, Wang, Inkol and Joyal, "Efficient
/// approximations for the arctangent function", IEEE Signal Processing Magazine 23(3), 2006;
/// tests/core/core_test.cpp checks it).
inline constexpr double kRoughAtan2Error = 0.0038;
inline constexpr double deg_to_rad(double deg) { return deg * kPi / 180.0; }
inline constexpr double rad_to_deg(double rad) { return rad * 180.0 / kPi; }

/// Unit vector at angle `rad`.
inline Vec2 unit(double rad) { return {std::cos(rad), std::sin(rad)}; }
/// `v` rotated by `rad`.
inline Vec2 rotate(const Vec2& v, double rad) {
  const double c = std::cos(rad), s = std::sin(rad);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}
/// 2D cross product (z of the 3D cross product).
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// A rigid 2D pose: position and heading. Also used as a transform from a local frame to a parent.
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  ///< heading in radians

  Vec2 position() const { return {x, y}; }
  /// A point given in this pose's frame, expressed in the parent frame.
  Vec2 to_parent(const Vec2& local) const { return position() + rotate(local, theta); }
  /// A point given in the parent frame, expressed in this pose's frame.
  Vec2 to_local(const Vec2& parent) const { return rotate(parent - position(), -theta); }
  /// This ∘ other: `other` is given in this pose's frame.
  Pose2D compose(const Pose2D& other) const;
  /// The inverse transform.
  Pose2D inverse() const;
  /// Distance between the positions.
  double distance_to(const Pose2D& o) const { return std::hypot(x - o.x, y - o.y); }
  friend bool operator==(const Pose2D&, const Pose2D&) = default;
};

/// A rectangle of half extents (half length along its heading, half width) centred at a pose.
struct OrientedBox {
  Pose2D pose;
  Vec2 half_extents{0.0, 0.0};

  /// The four corners, counter-clockwise, in the parent frame.
  std::array<Vec2, 4> corners() const;
  bool contains(const Vec2& p) const;
};

/// True if the boxes' interiors overlap (separating-axis test; touching does not count).
bool overlaps(const OrientedBox& a, const OrientedBox& b);

/// True if the box lies entirely inside the axis-aligned rectangle [lo, hi].
bool inside_rect(const OrientedBox& box, const Vec2& lo, const Vec2& hi);

/// Distance along the ray (origin + t*dir, dir unit, t >= 0) to segment [a, b], if it hits.
std::optional<double> ray_segment(const Vec2& origin, const Vec2& dir, const Vec2& a,
                                  const Vec2& b);

/// Distance along the ray (dir unit) to the first crossing of a circle's boundary, if any
/// (from inside the circle this is the exit point).
std::optional<double> ray_circle(const Vec2& origin, const Vec2& dir, const Vec2& center,
                                 double radius);

}  // namespace llsf::core
