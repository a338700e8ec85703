// SPDX-License-Identifier: MIT
// Ray casting against the field walls, the device footprints and dynamic circles (robots, pucks).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "llsf/core/geometry.h"
#include "llsf/kinematic/world_config.h"

namespace llsf::kinematic {

/// What a ray hit.
enum class HitKind : std::uint8_t { kNone, kWall, kDevice, kRobot, kPuck };

/// The nearest hit along a ray.
struct RayHit {
  double distance_m = 0.0;  ///< distance from the ray origin; max range if kind is kNone
  HitKind kind = HitKind::kNone;
  int index = -1;  ///< device index 0..15, or robot/puck index in the span given; -1 for walls/none
};

/// A dynamic obstacle seen by rays: a robot body or a puck.
struct Circle {
  Vec2 center{0.0, 0.0};
  double radius = 0.0;  ///< metres
  int index = -1;       ///< the caller's id, reported in RayHit::index
};

/// Ray casting against the static field (the 4 wall faces of the field boundary [0,W]x[0,H] seen
/// from inside, and the 16 device footprints) plus dynamic circles (robots, pucks). Built once
/// from a WorldConfig; immutable and thread-compatible afterwards (const methods may run
/// concurrently). Copyable and movable.
///
/// Faces are one-sided: a wall or box face is only seen from its outer side (the field interior
/// for walls, the outside for device boxes), so an origin inside a device footprint or outside
/// the field sees through those faces, and a face whose line passes exactly through the origin is
/// ignored. Circles whose closed interior contains the origin are ignored as well.
class RayCaster {
 public:
  /// Working memory for scan(): the beam direction table, rebuilt only when the beam count or
  /// increment changes. One per thread; a scan neither allocates nor calls trig per beam once the
  /// table matches.
  class ScanScratch {
   public:
    ScanScratch() = default;

   private:
    friend class RayCaster;
    double increment_rad_ = 0.0;
    int beams_ = -1;
    std::vector<double> cos_;  ///< cos(i * increment), i in [0, beams)
    std::vector<double> sin_;
  };

  explicit RayCaster(const WorldConfig& config);

  /// Nearest hit along one ray from `origin` in field-frame direction `angle_rad`, within
  /// max_range_m (inclusive); kind kNone and distance max_range_m if nothing is hit.
  RayHit cast(const Vec2& origin, double angle_rad, double max_range_m,
              std::span<const Circle> robots, std::span<const Circle> pucks) const;

  /// The faces (indices of walls and device faces) that a ray starting within reach_m - r of
  /// `center` may hit within a range r: the walls within reach_m, and every face of a box whose
  /// bounding circle comes within reach_m. Written to `faces` in index order, so that
  /// cast_among() against them gives the same result, ties included, as cast() against all.
  void faces_near(const Vec2& center, double reach_m, std::vector<int>& faces) const;
  /// cast() against the listed faces only (from faces_near()), in direction (dir_x, dir_y) =
  /// (cos, sin) of the ray's angle: several rays from about one place share the selection and
  /// the trigonometry.
  RayHit cast_among(const Vec2& origin, double dir_x, double dir_y, double max_range_m,
                    std::span<const int> faces, std::span<const Circle> robots,
                    std::span<const Circle> pucks) const;

  /// A whole scan: `n` beams at field-frame angles angle0_rad + i * increment_rad (i in [0, n)),
  /// each the distance to the nearest wall, device face or circle, +infinity where nothing lies
  /// within max_range_m. Writes n floats to ranges_out. The increment must be positive (unless
  /// n <= 1); a clockwise scan is the counter-clockwise one read backwards. Beams may cover more
  /// or less than a full turn. Thread-safe: uses a thread_local ScanScratch, whose table is
  /// rebuilt (n sin/cos calls; allocating only if n grows) when (n, increment_rad) differs from
  /// the thread's previous scan; alternate beam layouts should use the overload below.
  void scan(const Vec2& origin, double angle0_rad, double increment_rad, int n, double max_range_m,
            std::span<const Circle> circles, float* ranges_out) const;
  /// scan() with explicit working memory (not shared between threads).
  void scan(const Vec2& origin, double angle0_rad, double increment_rad, int n, double max_range_m,
            std::span<const Circle> circles, float* ranges_out, ScanScratch& scratch) const;

  /// Number of static segments (4 walls first, then 4 per device with a non-empty footprint).
  int segment_count() const { return static_cast<int>(segments_.size()); }

 private:
  /// One face a -> a + e; its visible side is the right-hand side of the direction a -> b.
  struct Segment {
    double ax, ay;    ///< start point
    double ex, ey;    ///< end minus start
    double inv_len2;  ///< 1 / |e|^2
    HitKind kind;
    int index;  ///< device index, -1 for walls
  };
  /// The faces of one device box, for culling by distance.
  struct DeviceGroup {
    double cx, cy;  ///< box centre
    double radius;  ///< half diagonal
    int first;      ///< first face in segments_
    int count;      ///< number of faces
  };

  void add_segment(const Vec2& a, const Vec2& b, HitKind kind, int index);

  std::vector<Segment> segments_;
  std::vector<DeviceGroup> groups_;
  int wall_count_ = 0;
};

}  // namespace llsf::kinematic
