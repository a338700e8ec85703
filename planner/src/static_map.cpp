// SPDX-License-Identifier: MIT
#include "static_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace llsf::planner::detail {

namespace {

MapBox make_box(std::string name, const OrientedBox& b) {
  MapBox m;
  m.name = std::move(name);
  m.center = b.pose.position();
  m.c = std::cos(b.pose.theta);
  m.s = std::sin(b.pose.theta);
  m.half = b.half_extents;
  // Axis-aligned bounds of the rotated box.
  const double ex = std::abs(m.c) * m.half.x() + std::abs(m.s) * m.half.y();
  const double ey = std::abs(m.s) * m.half.x() + std::abs(m.c) * m.half.y();
  m.lo = m.center - Vec2(ex, ey);
  m.hi = m.center + Vec2(ex, ey);
  return m;
}

// Distance from a local-frame point to the axis-aligned box [-half, half].
double local_box_distance(const Vec2& half, const Vec2& l) {
  const double dx = std::max(std::abs(l.x()) - half.x(), 0.0);
  const double dy = std::max(std::abs(l.y()) - half.y(), 0.0);
  return std::hypot(dx, dy);
}

// True if the local-frame segment [a, b] crosses the axis-aligned box [-half, half] (slab test).
bool local_segment_hits_box(const Vec2& half, const Vec2& a, const Vec2& b) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (a[k] < -half[k] || a[k] > half[k]) return false;
      continue;
    }
    double ta = (-half[k] - a[k]) / d[k];
    double tb = (half[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

StaticMap::StaticMap(const FieldMap& field, double radius_m)
    : width_(field.width_m), height_(field.height_m), radius_(radius_m) {
  for (const FieldDevice& d : field.devices) boxes_.push_back(make_box(d.name, d.footprint));
  for (const NamedBox& b : field.obstacles) boxes_.push_back(make_box(b.name, b.box));
}

double box_distance(const MapBox& b, const Vec2& p) {
  return local_box_distance(b.half, b.local(p));
}

double segment_point_distance(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

double box_segment_distance(const MapBox& box, const Vec2& a, const Vec2& b) {
  const Vec2 la = box.local(a), lb = box.local(b);
  if (local_segment_hits_box(box.half, la, lb)) return 0.0;
  // Disjoint convex sets: the minimum is attained at a segment end or a box corner.
  double d = std::min(local_box_distance(box.half, la), local_box_distance(box.half, lb));
  const double hx = box.half.x(), hy = box.half.y();
  const Vec2 corners[4] = {{hx, hy}, {-hx, hy}, {-hx, -hy}, {hx, -hy}};
  for (const Vec2& c : corners) d = std::min(d, segment_point_distance(la, lb, c));
  return d;
}

bool StaticMap::point_free(const Vec2& p) const {
  const double r = radius_;
  if (p.x() < r || p.y() < r || p.x() > width_ - r || p.y() > height_ - r) return false;
  for (const MapBox& b : boxes_) {
    // Bounding-box reject first: most boxes are far away.
    if (p.x() < b.lo.x() - r || p.x() > b.hi.x() + r || p.y() < b.lo.y() - r ||
        p.y() > b.hi.y() + r)
      continue;
    const Vec2 l = b.local(p);
    const double dx = std::max(std::abs(l.x()) - b.half.x(), 0.0);
    const double dy = std::max(std::abs(l.y()) - b.half.y(), 0.0);
    if (dx * dx + dy * dy < r * r) return false;
  }
  return true;
}

bool StaticMap::segment_free(const Vec2& a, const Vec2& b) const {
  // The free region inside the walls is convex: both ends inside means the segment is.
  if (!point_free(a) || !point_free(b)) return false;
  const double r = radius_;
  const Vec2 lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  for (const MapBox& box : boxes_) {
    if (hi.x() < box.lo.x() - r || lo.x() > box.hi.x() + r || hi.y() < box.lo.y() - r ||
        lo.y() > box.hi.y() + r)
      continue;
    if (box_segment_distance(box, a, b) < r) return false;
  }
  return true;
}

double StaticMap::signed_distance(const Vec2& p, int* which) const {
  double best = p.x();
  int w = -1;
  const double walls[3] = {width_ - p.x(), p.y(), height_ - p.y()};
  for (int k = 0; k < 3; ++k) {
    if (walls[k] < best) {
      best = walls[k];
      w = -2 - k;
    }
  }
  for (int i = 0; i < static_cast<int>(boxes_.size()); ++i) {
    const MapBox& b = boxes_[i];
    const Vec2 l = b.local(p);
    const double ox = std::abs(l.x()) - b.half.x(), oy = std::abs(l.y()) - b.half.y();
    // Outside: Euclidean distance; inside: minus the depth to the nearest side.
    const double d = (ox > 0.0 || oy > 0.0) ? std::hypot(std::max(ox, 0.0), std::max(oy, 0.0))
                                            : std::max(ox, oy);
    if (d < best) {
      best = d;
      w = i;
    }
  }
  if (which) *which = w;
  return best;
}

std::string StaticMap::obstacle_name(int which) const {
  switch (which) {
    case -1:
      return "wall x=0";
    case -2:
      return "wall x=width";
    case -3:
      return "wall y=0";
    case -4:
      return "wall y=height";
    default:
      break;
  }
  if (which >= 0 && which < static_cast<int>(boxes_.size())) return boxes_[which].name;
  return "?";
}

bool discs_free(std::span<const DiscObstacle> discs, double r, const Vec2& p) {
  for (const DiscObstacle& d : discs) {
    const double rr = r + d.radius_m;
    if ((p - d.position).squaredNorm() < rr * rr) return false;
  }
  return true;
}

bool discs_segment_free(std::span<const DiscObstacle> discs, double r, const Vec2& a,
                        const Vec2& b) {
  for (const DiscObstacle& d : discs) {
    if (segment_point_distance(a, b, d.position) < r + d.radius_m) return false;
  }
  return true;
}

}  // namespace llsf::planner::detail
