// SPDX-License-Identifier: MIT
// RayCaster: known distances, hit kinds, and scan() against a brute-force reference.
#include "raycast.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "llsf/core/assert.h"
#include "llsf/core/geometry.h"
#include "llsf/core/rng.h"
#include "llsf/kinematic/world_config.h"

using namespace llsf::kinematic;
using llsf::core::kPi;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

/// The 2013 field with the default device footprints.
WorldConfig field_2013() { return WorldConfig::default_2013(); }

/// A field without devices (all footprints empty).
WorldConfig empty_field() { return WorldConfig{}; }

/// Brute force: every face of the walls and of every footprint, every circle not containing the
/// origin, with the core helpers. +infinity beyond max range.
double reference_range(const WorldConfig& config, const Vec2& origin, double angle,
                       double max_range, const std::vector<Circle>& circles) {
  const Vec2 dir = llsf::core::unit(angle);
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](std::optional<double> t) {
    if (t && *t < best) best = *t;
  };
  const double w = config.field.width_m, h = config.field.height_m;
  const Vec2 field[4] = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  for (int k = 0; k < 4; ++k) {
    consider(llsf::core::ray_segment(origin, dir, field[k], field[(k + 1) % 4]));
  }
  for (const DeviceConfig& d : config.devices) {
    const auto c = d.footprint().corners();
    for (int k = 0; k < 4; ++k) {
      consider(llsf::core::ray_segment(origin, dir, c[k], c[(k + 1) % 4]));
    }
  }
  for (const Circle& c : circles) {
    if ((origin - c.center).norm() <= c.radius) continue;
    consider(llsf::core::ray_circle(origin, dir, c.center, c.radius));
  }
  return best <= max_range ? best : std::numeric_limits<double>::infinity();
}

bool inside_any_footprint(const WorldConfig& config, const Vec2& p, double margin) {
  for (const DeviceConfig& d : config.devices) {
    llsf::core::OrientedBox box = d.footprint();
    box.half_extents += Vec2(margin, margin);
    if (box.contains(p)) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("raycast: empty field reads the walls") {
  const WorldConfig config = empty_field();
  const RayCaster caster(config);
  CHECK(caster.segment_count() == 4);
  const Vec2 origin(2.8, 2.8);
  std::vector<float> ranges(360);
  caster.scan(origin, 0.0, 2 * kPi / 360, 360, 10.0, {}, ranges.data());
  CHECK(ranges[0] == doctest::Approx(5.6 - 2.8).epsilon(1e-7));
  CHECK(ranges[90] == doctest::Approx(5.6 - 2.8).epsilon(1e-7));
  CHECK(ranges[180] == doctest::Approx(2.8).epsilon(1e-7));
  CHECK(ranges[45] == doctest::Approx(2.8 * std::sqrt(2.0)).epsilon(1e-7));

  const Vec2 off(1.0, 2.0);
  caster.scan(off, kPi / 2, 2 * kPi / 360, 360, 10.0, {}, ranges.data());
  CHECK(ranges[0] == doctest::Approx(3.6).epsilon(1e-7));    // +y
  CHECK(ranges[90] == doctest::Approx(1.0).epsilon(1e-7));   // -x
  CHECK(ranges[180] == doctest::Approx(2.0).epsilon(1e-7));  // -y
  CHECK(ranges[270] == doctest::Approx(4.6).epsilon(1e-7));  // +x

  const RayHit hit = caster.cast(origin, 0.0, 10.0, {}, {});
  CHECK(hit.kind == HitKind::kWall);
  CHECK(hit.index == -1);
  CHECK(hit.distance_m == doctest::Approx(2.8));
}

TEST_CASE("raycast: beyond max range is +infinity, cast reports max range") {
  const RayCaster caster(empty_field());
  std::vector<float> ranges(360);
  caster.scan({2.8, 2.8}, 0.3, 2 * kPi / 360, 360, 1.0, {}, ranges.data());
  for (float r : ranges) CHECK(r == kInfF);
  caster.scan({0.5, 2.8}, 0.0, 2 * kPi / 360, 360, 1.0, {}, ranges.data());
  CHECK(ranges[180] == doctest::Approx(0.5));
  CHECK(ranges[0] == kInfF);
  const RayHit miss = caster.cast({2.8, 2.8}, 1.0, 1.0, {}, {});
  CHECK(miss.kind == HitKind::kNone);
  CHECK(miss.index == -1);
  CHECK(miss.distance_m == 1.0);
}

TEST_CASE("raycast: a device straight ahead reads its face distance") {
  WorldConfig config = empty_field();
  DeviceConfig& d = config.devices[5];
  d.pose = {4.0, 2.8, kPi};  // facing the robot
  d.body_depth_m = 0.2;
  d.body_width_m = 0.3;
  const RayCaster caster(config);
  CHECK(caster.segment_count() == 8);

  std::vector<float> ranges(360);
  caster.scan({2.8, 2.8}, 0.0, 2 * kPi / 360, 360, 5.6, {}, ranges.data());
  CHECK(ranges[0] == doctest::Approx(1.1).epsilon(1e-7));
  CHECK(ranges[180] == doctest::Approx(2.8).epsilon(1e-7));

  const RayHit hit = caster.cast({2.8, 2.8}, 0.0, 5.6, {}, {});
  CHECK(hit.kind == HitKind::kDevice);
  CHECK(hit.index == 5);
  CHECK(hit.distance_m == doctest::Approx(1.1));
  // Past the box's side the wall is seen.
  const RayHit past = caster.cast({2.8, 3.2}, 0.0, 5.6, {}, {});
  CHECK(past.kind == HitKind::kWall);
  CHECK(past.distance_m == doctest::Approx(2.8));
  // From the far side the back face is seen, and from inside the box nothing of it.
  const RayHit back = caster.cast({5.0, 2.8}, kPi, 5.6, {}, {});
  CHECK(back.kind == HitKind::kDevice);
  CHECK(back.distance_m == doctest::Approx(0.9));
  const RayHit inside = caster.cast({4.0, 2.8}, 0.0, 5.6, {}, {});
  CHECK(inside.kind == HitKind::kWall);
  CHECK(inside.distance_m == doctest::Approx(1.6));
}

TEST_CASE("raycast: circles straight ahead read d - r and report robot or puck") {
  const RayCaster caster(empty_field());
  const Vec2 origin(2.8, 2.8);
  const std::vector<Circle> robots = {{{3.5, 2.8}, 0.185, 2}, {{2.8, 1.0}, 0.185, 0}};
  const std::vector<Circle> pucks = {{{3.2, 2.8}, 0.0375, 7}, {{1.0, 2.8}, 0.0375, 3}};

  std::vector<float> ranges(360);
  caster.scan(origin, 0.0, 2 * kPi / 360, 360, 5.6, robots, ranges.data());
  CHECK(ranges[0] == doctest::Approx(0.7 - 0.185).epsilon(1e-7));
  CHECK(ranges[270] == doctest::Approx(1.8 - 0.185).epsilon(1e-7));
  CHECK(ranges[180] == doctest::Approx(2.8).epsilon(1e-7));

  RayHit hit = caster.cast(origin, 0.0, 5.6, robots, {});
  CHECK(hit.kind == HitKind::kRobot);
  CHECK(hit.index == 2);
  CHECK(hit.distance_m == doctest::Approx(0.515));
  hit = caster.cast(origin, 0.0, 5.6, robots, pucks);  // the puck is nearer
  CHECK(hit.kind == HitKind::kPuck);
  CHECK(hit.index == 7);
  CHECK(hit.distance_m == doctest::Approx(0.4 - 0.0375));
  hit = caster.cast(origin, kPi, 5.6, robots, pucks);
  CHECK(hit.kind == HitKind::kPuck);
  CHECK(hit.index == 3);
  hit = caster.cast(origin, -kPi / 2, 5.6, robots, pucks);
  CHECK(hit.kind == HitKind::kRobot);
  CHECK(hit.index == 0);
  hit = caster.cast(origin, kPi / 2, 5.6, robots, pucks);
  CHECK(hit.kind == HitKind::kWall);

  // A circle containing the origin (the sensor's own body) is ignored.
  const std::vector<Circle> own = {{origin, 0.185, 1}};
  caster.scan(origin, 0.0, 2 * kPi / 360, 360, 5.6, own, ranges.data());
  CHECK(ranges[0] == doctest::Approx(2.8).epsilon(1e-7));
  CHECK(caster.cast(origin, 0.0, 5.6, own, {}).kind == HitKind::kWall);
}

TEST_CASE("raycast: device hits in the 2013 layout") {
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  CHECK(caster.segment_count() == 4 + 4 * kDeviceCount);
  // Below M1 (at y = 1.68, facing down): its front face lies offset + depth / 2 below the pose.
  const DeviceConfig& m1 = config.devices[0];
  const double m1_front_y = m1.pose.y - (m1.body_offset_m + 0.5 * m1.body_depth_m);
  RayHit hit = caster.cast({m1.pose.x, 1.0}, kPi / 2, 5.6, {}, {});
  CHECK(hit.kind == HitKind::kDevice);
  CHECK(hit.index == 0);
  CHECK(hit.distance_m == doctest::Approx(m1_front_y - 1.0));
  // Towards R1 in the bottom-right corner, along its facing line.
  const DeviceConfig& r1 = config.devices[10];
  const Vec2 from = r1.pose.position() + 1.0 * llsf::core::unit(r1.pose.theta);
  hit = caster.cast(from, r1.pose.theta + kPi, 5.6, {}, {});
  CHECK(hit.kind == HitKind::kDevice);
  CHECK(hit.index == 10);
  CHECK(hit.distance_m == doctest::Approx(1.0 - (r1.body_offset_m + 0.5 * r1.body_depth_m)));
}

TEST_CASE("raycast: scan agrees with cast beam by beam") {
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  const std::vector<Circle> circles = {
      {{1.2, 1.0}, 0.185, 0}, {{4.5, 4.4}, 0.185, 1}, {{2.2, 2.5}, 0.0375, 2}};
  const Vec2 origin(2.2, 3.1);
  const double angle0 = 0.7, inc = 2 * kPi / 360;
  std::vector<float> ranges(360);
  caster.scan(origin, angle0, inc, 360, 5.6, circles, ranges.data());
  for (int i = 0; i < 360; ++i) {
    const RayHit hit = caster.cast(origin, angle0 + i * inc, 5.6, circles, {});
    if (hit.kind == HitKind::kNone) {
      CHECK(ranges[i] == kInfF);
    } else {
      CHECK(std::abs(ranges[i] - hit.distance_m) <= 1e-6);
    }
  }
}

TEST_CASE("raycast: cast matches the brute-force reference, also with short ranges") {
  // cast() looks at a box's faces only when the ray passes its bounding circle within range:
  // random rays near devices and short ranges test that the culling never loses a hit.
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  llsf::core::RandomStream rng(20131126);
  const std::vector<Circle> circles = {{{1.2, 1.0}, 0.185, 0}, {{2.2, 2.5}, 0.0375, 1}};
  const double w = config.field.width_m, h = config.field.height_m;
  int hits = 0, mismatches = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Vec2 origin;
    do {
      if (trial % 2 == 0) {
        origin = Vec2(rng.uniform(0.05, w - 0.05), rng.uniform(0.05, h - 0.05));
      } else {
        const DeviceConfig& d = config.devices[static_cast<std::size_t>(
            rng.uniform_int(0, static_cast<std::int64_t>(config.devices.size()) - 1))];
        origin = Vec2(d.pose.x + rng.uniform(-0.6, 0.6), d.pose.y + rng.uniform(-0.6, 0.6));
      }
    } while (inside_any_footprint(config, origin, 1e-3) || origin.x() <= 0.0 || origin.y() <= 0.0 ||
             origin.x() >= w || origin.y() >= h);
    const double angle = rng.uniform(-kPi, kPi);
    const double max_range = rng.uniform(0.05, 2.0);
    const double ref = reference_range(config, origin, angle, max_range, circles);
    const RayHit hit = caster.cast(origin, angle, max_range, circles, {});
    if (std::isinf(ref)) {
      if (hit.kind != HitKind::kNone) ++mismatches;
    } else {
      ++hits;
      if (hit.kind == HitKind::kNone || std::abs(hit.distance_m - ref) > 1e-9) ++mismatches;
    }
  }
  CHECK(hits > 5000);
  CHECK(mismatches == 0);
}

TEST_CASE("raycast: cast_among the faces near a centre is cast, ties and misses included") {
  // The optical sensors cast two short rays from about one place: faces_near() keeps the faces
  // within reach of the robot's centre, and cast_among() must give exactly what cast() gives.
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  llsf::core::RandomStream rng(20261126);
  const double w = config.field.width_m, h = config.field.height_m;
  std::vector<int> faces;
  int hits = 0, culled = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const DeviceConfig& d = config.devices[static_cast<std::size_t>(
        rng.uniform_int(0, static_cast<std::int64_t>(config.devices.size()) - 1))];
    const Vec2 centre =
        trial % 3 == 0 ? Vec2(rng.uniform(0.05, w - 0.05), rng.uniform(0.05, h - 0.05))
                       : Vec2(d.pose.x + rng.uniform(-0.8, 0.8), d.pose.y + rng.uniform(-0.8, 0.8));
    const double start = rng.uniform(0.0, 0.3), range = rng.uniform(0.01, 0.6);
    const Vec2 origin = centre + llsf::core::unit(rng.uniform(-kPi, kPi)) * start;
    const double angle = rng.uniform(-kPi, kPi);
    const std::vector<Circle> robots = {
        {centre + Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1)), 0.185, 4}};
    const std::vector<Circle> pucks = {
        {origin + llsf::core::unit(angle) * rng.uniform(0.0, 0.7), 0.0375, 7},
        {centre + Vec2(rng.uniform(-1, 1), rng.uniform(-1, 1)), 0.0375, 9}};
    caster.faces_near(centre, start + range, faces);
    culled += caster.segment_count() - static_cast<int>(faces.size());
    const RayHit all = caster.cast(origin, angle, range, robots, pucks);
    const RayHit near =
        caster.cast_among(origin, std::cos(angle), std::sin(angle), range, faces, robots, pucks);
    if (all.kind != HitKind::kNone) ++hits;
    REQUIRE(near.kind == all.kind);
    REQUIRE(near.index == all.index);
    REQUIRE(near.distance_m == all.distance_m);
  }
  CHECK(hits > 5000);
  CHECK(culled > 20000 * (caster.segment_count() / 2));  // most faces are left out
}

TEST_CASE("raycast: scan matches the brute-force reference from random poses") {
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  llsf::core::RandomStream rng(20130612);
  RayCaster::ScanScratch scratch;

  struct Fan {
    int n;
    double increment;
  };
  const Fan fans[] = {
      {360, 2 * kPi / 360}, {361, 2 * kPi / 361},
      {361, 2 * kPi / 360},                        // wraps by one beam
      {100, 2 * kPi / 100}, {100, 0.01},           // a partial fan
      {720, 2 * kPi / 720}, {720, 2 * kPi / 360},  // two turns
      {1, 2 * kPi / 360},   {7, 1.3},              // beams far apart
  };
  const double max_ranges[] = {5.6, 8.0, 2.0, 0.6};
  const double w = config.field.width_m, h = config.field.height_m;

  int scans = 0, beams = 0, hits = 0, misses = 0, mismatches = 0;
  std::vector<float> ranges;
  std::vector<float> ranges_tl;
  for (int trial = 0; trial < 2400; ++trial) {
    // Half the origins anywhere, half in a device's neighbourhood; never inside a footprint.
    Vec2 origin;
    do {
      if (trial % 2 == 0) {
        origin = {rng.uniform(0.0, w), rng.uniform(0.0, h)};
      } else {
        const DeviceConfig& d = config.devices[rng.uniform_int(0, kDeviceCount - 1)];
        const auto box = d.footprint();
        const double reach = box.half_extents.norm() + 0.3;
        origin = box.pose.position() + Vec2(rng.uniform(-reach, reach), rng.uniform(-reach, reach));
      }
    } while (origin.x() <= 1e-3 || origin.y() <= 1e-3 || origin.x() >= w - 1e-3 ||
             origin.y() >= h - 1e-3 || inside_any_footprint(config, origin, 1e-6));

    // Random robots and pucks; some may contain the origin (and must then be ignored).
    std::vector<Circle> circles;
    const int n_circles = static_cast<int>(rng.uniform_int(0, 5));
    for (int c = 0; c < n_circles; ++c) {
      const double r = rng.bernoulli(0.5) ? 0.185 : 0.0375;
      Vec2 center;
      if (rng.bernoulli(0.5)) {
        center = {rng.uniform(0.0, w), rng.uniform(0.0, h)};
      } else {
        center = origin + llsf::core::unit(rng.uniform(-kPi, kPi)) * rng.uniform(0.0, 1.0);
      }
      circles.push_back({center, r, c});
    }

    const Fan& fan = fans[trial % std::size(fans)];
    const double max_range = max_ranges[rng.uniform_int(0, 3)];
    const double angle0 = rng.uniform(-4.0, 4.0);  // not normalised on purpose
    ranges.assign(fan.n, -1.0f);
    ranges_tl.assign(fan.n, -1.0f);
    caster.scan(origin, angle0, fan.increment, fan.n, max_range, circles, ranges.data(), scratch);
    caster.scan(origin, angle0, fan.increment, fan.n, max_range, circles, ranges_tl.data());
    ++scans;
    for (int i = 0; i < fan.n; ++i) {
      const double ref =
          reference_range(config, origin, angle0 + i * fan.increment, max_range, circles);
      ++beams;
      const bool ok = std::isinf(ref) ? ranges[i] == kInfF : std::abs(ranges[i] - ref) <= 1e-6;
      ++(std::isinf(ref) ? misses : hits);
      if (!ok || ranges_tl[i] != ranges[i]) {
        ++mismatches;
        if (mismatches <= 5) {
          MESSAGE("mismatch: origin (" << origin.x() << ", " << origin.y() << ") angle0 " << angle0
                                       << " n " << fan.n << " beam " << i << " ref " << ref
                                       << " got " << ranges[i]);
        }
      }
    }
  }
  CHECK(scans >= 2000);
  CHECK(hits > 100000);
  CHECK(misses > 1000);
  CHECK(beams > 500000);
  CHECK(mismatches == 0);
}

TEST_CASE("raycast: beams exactly through a corner between two visible faces do not leak") {
  // A beam aimed exactly at a wall corner, or at a box corner whose both faces are seen, must
  // stop there (or before, if something nearer is in the way), whatever the rounding.
  const WorldConfig config = field_2013();
  const RayCaster caster(config);
  llsf::core::RandomStream rng(7);
  const double w = config.field.width_m, h = config.field.height_m;
  std::vector<Vec2> corners = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  std::vector<float> ranges(360);
  int aimed = 0, leaks = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Vec2 origin;
    do {
      origin = {rng.uniform(0.05, w - 0.05), rng.uniform(0.05, h - 0.05)};
    } while (inside_any_footprint(config, origin, 1e-6));
    std::vector<Vec2> targets = corners;
    for (const DeviceConfig& d : config.devices) {
      const auto c = d.footprint().corners();
      for (int k = 0; k < 4; ++k) {
        const Vec2& prev = c[(k + 3) % 4];
        const Vec2& next = c[(k + 1) % 4];
        // Both faces at c[k] are seen when the origin is outside both their lines.
        const bool in_seen = llsf::core::cross(c[k] - prev, origin - prev) < 0.0;
        const bool out_seen = llsf::core::cross(next - c[k], origin - c[k]) < 0.0;
        if (in_seen && out_seen) targets.push_back(c[k]);
      }
    }
    for (const Vec2& target : targets) {
      const Vec2 v = target - origin;
      const double angle = std::atan2(v.y(), v.x());
      const double inc = 2 * kPi / 360;
      for (int beam : {0, 137, 359}) {
        caster.scan(origin, angle - beam * inc, inc, 360, 8.0, {}, ranges.data());
        ++aimed;
        if (!(ranges[beam] <= v.norm() + 1e-6)) ++leaks;
      }
      const RayHit hit = caster.cast(origin, angle, 8.0, {}, {});
      if (!(hit.kind != HitKind::kNone && hit.distance_m <= v.norm() + 1e-6)) ++leaks;
    }
  }
  CHECK(aimed > 3000);
  CHECK(leaks == 0);
}

TEST_CASE("raycast: degenerate scans") {
  const RayCaster caster(empty_field());
  std::vector<float> ranges(4, -1.0f);
  caster.scan({2.8, 2.8}, 0.0, 0.1, 0, 5.6, {}, ranges.data());
  CHECK(ranges[0] == -1.0f);  // n = 0 writes nothing
  caster.scan({2.8, 2.8}, kPi, -1.0, 1, 5.6, {}, ranges.data());
  CHECK(ranges[0] == doctest::Approx(2.8));  // one beam ignores the increment
  CHECK_THROWS_AS(caster.scan({2.8, 2.8}, 0.0, -0.1, 4, 5.6, {}, ranges.data()),
                  llsf::core::AssertionError);
  CHECK_THROWS_AS(caster.scan({2.8, 2.8}, 0.0, 0.0, 4, 5.6, {}, ranges.data()),
                  llsf::core::AssertionError);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(caster.scan({nan, 2.8}, 0.0, 0.1, 4, 5.6, {}, ranges.data()),
                  llsf::core::AssertionError);
  // A circle with a NaN centre is never hit (and does not hang the rasteriser).
  const std::vector<Circle> bad = {{{nan, 1.0}, 0.2, 0}};
  caster.scan({2.8, 2.8}, 0.0, kPi / 2, 4, 5.6, bad, ranges.data());
  CHECK(ranges[1] == doctest::Approx(2.8));
}
