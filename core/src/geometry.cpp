// SPDX-License-Identifier: MIT
#include "llsf/core/geometry.h"

#include <algorithm>
#include <limits>

namespace llsf::core {

double normalize_angle(double rad) {
  // Already in (-pi, pi]: remainder() would return it unchanged (|rad / 2 pi| <= 1/2, a tie
  // rounding to the even quotient 0), so skip the libm call (most calls).
  if (rad > -kPi && rad <= kPi) return rad;
  double a = std::remainder(rad, 2.0 * kPi);  // in [-pi, pi]
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

double angle_diff(double to, double from) { return normalize_angle(to - from); }

double rough_atan2(double y, double x) {
  // atan(t) ~ (pi / 4) t + 0.273 t (1 - t) on [0, 1], folded onto the other octants.
  const double ax = std::abs(x), ay = std::abs(y);
  const bool steep = ay > ax;
  const double t = steep ? ax / ay : (ax > 0.0 ? ay / ax : 0.0);
  double a = (0.25 * kPi + 0.273 * (1.0 - t)) * t;
  a = steep ? 0.5 * kPi - a : a;
  a = x < 0.0 ? kPi - a : a;
  return y < 0.0 ? -a : a;
}

Pose2D Pose2D::compose(const Pose2D& other) const {
  const Vec2 p = to_parent(other.position());
  return {p.x(), p.y(), normalize_angle(theta + other.theta)};
}

Pose2D Pose2D::inverse() const {
  const Vec2 p = rotate(Vec2(-x, -y), -theta);
  return {p.x(), p.y(), normalize_angle(-theta)};
}

std::array<Vec2, 4> OrientedBox::corners() const {
  const double hx = half_extents.x(), hy = half_extents.y();
  return {pose.to_parent({hx, -hy}), pose.to_parent({hx, hy}), pose.to_parent({-hx, hy}),
          pose.to_parent({-hx, -hy})};
}

bool OrientedBox::contains(const Vec2& p) const {
  const Vec2 l = pose.to_local(p);
  return std::abs(l.x()) <= half_extents.x() && std::abs(l.y()) <= half_extents.y();
}

namespace {
// Projects the corners onto an axis and returns [min, max].
std::pair<double, double> project(const std::array<Vec2, 4>& c, const Vec2& axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec2& p : c) {
    const double d = p.dot(axis);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return {lo, hi};
}
}  // namespace

bool overlaps(const OrientedBox& a, const OrientedBox& b) {
  constexpr double kTouch = 1e-9;  // touching boxes are not overlapping
  const auto ca = a.corners(), cb = b.corners();
  const std::array<Vec2, 4> axes = {unit(a.pose.theta), unit(a.pose.theta + kPi / 2),
                                    unit(b.pose.theta), unit(b.pose.theta + kPi / 2)};
  for (const Vec2& axis : axes) {
    const auto [alo, ahi] = project(ca, axis);
    const auto [blo, bhi] = project(cb, axis);
    if (ahi <= blo + kTouch || bhi <= alo + kTouch) return false;
  }
  return true;
}

bool inside_rect(const OrientedBox& box, const Vec2& lo, const Vec2& hi) {
  constexpr double kEps = 1e-9;
  for (const Vec2& p : box.corners()) {
    if (p.x() < lo.x() - kEps || p.y() < lo.y() - kEps || p.x() > hi.x() + kEps ||
        p.y() > hi.y() + kEps) {
      return false;
    }
  }
  return true;
}

std::optional<double> ray_segment(const Vec2& origin, const Vec2& dir, const Vec2& a,
                                  const Vec2& b) {
  const Vec2 e = b - a;
  const double denom = cross(dir, e);
  if (std::abs(denom) < 1e-15) return std::nullopt;  // parallel
  const Vec2 w = a - origin;
  const double t = cross(w, e) / denom;
  const double u = cross(w, dir) / denom;
  if (t < 0.0 || u < 0.0 || u > 1.0) return std::nullopt;
  return t;
}

std::optional<double> ray_circle(const Vec2& origin, const Vec2& dir, const Vec2& center,
                                 double radius) {
  const Vec2 m = origin - center;
  const double b = m.dot(dir);
  const double c = m.squaredNorm() - radius * radius;
  const double disc = b * b - c;
  if (disc < 0.0) return std::nullopt;
  const double sq = std::sqrt(disc);
  double t = -b - sq;
  if (t < 0.0) t = -b + sq;
  if (t < 0.0) return std::nullopt;
  return t;
}

}  // namespace llsf::core
