// SPDX-License-Identifier: MIT
// The static map: walls and oriented boxes with precomputed frames, and the hand-written exact
// checks of points and segments against them (the planner's hot path: a few ns per box).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "llsf/planner/field_map.h"
#include "llsf/planner/planner.h"

namespace llsf::planner::detail {

/// One obstacle box with its frame precomputed for fast local-frame transforms.
struct MapBox {
  std::string name;
  Vec2 center{0.0, 0.0};
  double c = 1.0;  // cos of the heading
  double s = 0.0;  // sin of the heading
  Vec2 half{0.0, 0.0};
  Vec2 lo{0.0, 0.0};  // axis-aligned bounds of the box itself
  Vec2 hi{0.0, 0.0};

  /// `p` in the box frame.
  Vec2 local(const Vec2& p) const {
    const Vec2 d = p - center;
    return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
  }
};

/// Walls around [0, width] x [0, height] plus boxes. Immutable after construction.
class StaticMap {
 public:
  StaticMap(const FieldMap& field, double radius_m);

  double width() const { return width_; }
  double height() const { return height_; }
  double radius() const { return radius_; }
  const std::vector<MapBox>& boxes() const { return boxes_; }

  /// A disc of the map radius at `p` touches neither walls nor boxes.
  bool point_free(const Vec2& p) const;
  /// A disc of the map radius swept along [a, b] touches neither walls nor boxes (exact).
  bool segment_free(const Vec2& a, const Vec2& b) const;
  /// Signed distance from `p` to the nearest wall or box (negative inside), and which one
  /// (index into boxes(), or -1 .. -4 for the walls x=0, x=width, y=0, y=height).
  double signed_distance(const Vec2& p, int* which = nullptr) const;
  /// Name of an obstacle index as returned by signed_distance().
  std::string obstacle_name(int which) const;

 private:
  double width_;
  double height_;
  double radius_;
  std::vector<MapBox> boxes_;
};

/// Distance from `p` to the box (0 inside).
double box_distance(const MapBox& b, const Vec2& p);
/// Distance between the segment [a, b] and the box (0 if they intersect).
double box_segment_distance(const MapBox& box, const Vec2& a, const Vec2& b);
/// Distance from `p` to the segment [a, b].
double segment_point_distance(const Vec2& a, const Vec2& b, const Vec2& p);

/// Discs: a robot of radius `r` at `p` (or swept along [a, b]) keeps clear of every disc.
bool discs_free(std::span<const DiscObstacle> discs, double r, const Vec2& p);
bool discs_segment_free(std::span<const DiscObstacle> discs, double r, const Vec2& a,
                        const Vec2& b);

}  // namespace llsf::planner::detail
