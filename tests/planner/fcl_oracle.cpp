// SPDX-License-Identifier: MIT
#include "fcl_oracle.h"

#include <fcl/fcl.h>

#include <cmath>
#include <limits>
#include <vector>

namespace llsf::test {

namespace {
// Boxes are extruded to this height; the probes sit at z = 0 in their middle.
constexpr double kHeight = 1.0;
// A point is a sphere and a segment a capsule of this radius (FCL has no point or segment
// shape); it is added back.
constexpr double kProbe = 1e-4;
constexpr double kWall = 1.0;  // wall boxes lie outside the field, this thick

/// FCL's own GJK with a tight tolerance (libccd's, the default, is off by up to ~0.1 mm for a
/// capsule).
fcl::DistanceRequestd tight_request() {
  fcl::DistanceRequestd r;
  r.distance_tolerance = 1e-9;
  r.gjk_solver_type = fcl::GST_INDEP;
  return r;
}

struct Query {
  const fcl::CollisionObjectd* probe = nullptr;
  fcl::DistanceRequestd request = tight_request();
  double min = std::numeric_limits<double>::infinity();
  int which = 0;
};

bool on_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data, double& dist) {
  auto* q = static_cast<Query*>(data);
  const fcl::CollisionObjectd* other = o1 == q->probe ? o2 : o1;
  fcl::DistanceResultd result;
  fcl::distance(o1, o2, q->request, result);
  if (result.min_distance < q->min) {
    q->min = result.min_distance;
    q->which = *static_cast<const int*>(other->getUserData());
  }
  dist = q->min;
  return q->min <= 0.0;  // touching an obstacle: nothing is nearer
}

/// A probe for the segment [a, b]: a sphere for a point, else a capsule along it.
fcl::CollisionObjectd segment_probe(const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double len = d.norm();
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  const Vec2 mid = 0.5 * (a + b);
  tf.translation() = fcl::Vector3d(mid.x(), mid.y(), 0.0);
  if (len < 1e-12) return fcl::CollisionObjectd(std::make_shared<fcl::Sphered>(kProbe), tf);
  // The capsule's axis is its local z: turn it into the segment's direction.
  tf.linear() = fcl::Quaterniond::FromTwoVectors(fcl::Vector3d::UnitZ(),
                                                 fcl::Vector3d(d.x() / len, d.y() / len, 0.0))
                    .toRotationMatrix();
  return fcl::CollisionObjectd(std::make_shared<fcl::Capsuled>(kProbe, len), tf);
}
}  // namespace

struct FclOracle::Impl {
  std::vector<int> ids;  // user data: obstacle index as StaticMap::signed_distance
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DynamicAABBTreeCollisionManagerd manager;

  void add(int id, double cx, double cy, double theta, double sx, double sy) {
    auto shape = std::make_shared<fcl::Boxd>(sx, sy, kHeight);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = fcl::Vector3d(cx, cy, 0.0);
    tf.linear() = fcl::AngleAxisd(theta, fcl::Vector3d::UnitZ()).toRotationMatrix();
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(shape, tf));
    ids.push_back(id);
  }

  double nearest(fcl::CollisionObjectd& probe, int* which) {
    Query q;
    q.probe = &probe;
    manager.distance(&probe, &q, on_pair);
    if (which) *which = q.which;
    return q.min <= 0.0 ? 0.0 : q.min + kProbe;
  }
};

FclOracle::FclOracle(const planner::detail::StaticMap& map) : impl_(std::make_unique<Impl>()) {
  const double w = map.width(), h = map.height();
  impl_->ids.reserve(map.boxes().size() + 4);
  impl_->add(-1, -0.5 * kWall, 0.5 * h, 0.0, kWall, h + 2 * kWall);
  impl_->add(-2, w + 0.5 * kWall, 0.5 * h, 0.0, kWall, h + 2 * kWall);
  impl_->add(-3, 0.5 * w, -0.5 * kWall, 0.0, w + 2 * kWall, kWall);
  impl_->add(-4, 0.5 * w, h + 0.5 * kWall, 0.0, w + 2 * kWall, kWall);
  for (int i = 0; i < static_cast<int>(map.boxes().size()); ++i) {
    const planner::detail::MapBox& b = map.boxes()[static_cast<std::size_t>(i)];
    impl_->add(i, b.center.x(), b.center.y(), std::atan2(b.s, b.c), 2 * b.half.x(), 2 * b.half.y());
  }
  // The ids vector is complete: user data pointers into it stay valid.
  for (std::size_t k = 0; k < impl_->objects.size(); ++k) {
    impl_->objects[k]->setUserData(&impl_->ids[k]);
    impl_->manager.registerObject(impl_->objects[k].get());
  }
  impl_->manager.setup();
}

FclOracle::~FclOracle() = default;

double FclOracle::distance(const Vec2& p, int* which) const {
  return segment_distance(p, p, which);
}

double FclOracle::segment_distance(const Vec2& a, const Vec2& b, int* which) const {
  fcl::CollisionObjectd probe = segment_probe(a, b);
  return impl_->nearest(probe, which);
}

double FclOracle::segment_disc_distance(const Vec2& a, const Vec2& b, const Vec2& c, double r) {
  fcl::CollisionObjectd probe = segment_probe(a, b);
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation() = fcl::Vector3d(c.x(), c.y(), 0.0);
  const fcl::CollisionObjectd disc(std::make_shared<fcl::Cylinderd>(r, kHeight), tf);
  fcl::DistanceResultd result;
  fcl::distance(&probe, &disc, tight_request(), result);
  return result.min_distance <= 0.0 ? 0.0 : result.min_distance + kProbe;
}

}  // namespace llsf::test
