// SPDX-License-Identifier: MIT
#include "fcl_distance.h"

#include <fcl/fcl.h>

#include <limits>
#include <vector>

namespace llsf::planner::detail {

namespace {
// Boxes are extruded to this height; the query sphere sits at z = 0 in their middle, so every
// distance is the planar one.
constexpr double kHeight = 1.0;
// The query is a sphere of this radius (FCL has no point shape); it is added back.
constexpr double kProbe = 1e-4;
constexpr double kWall = 1.0;  // wall boxes lie outside the field, this thick

struct Query {
  const fcl::CollisionObjectd* probe = nullptr;
  fcl::DistanceRequestd request;
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
  return q->min <= 0.0;  // inside an obstacle: nothing is nearer
}
}  // namespace

struct FclDistance::Impl {
  std::vector<int> ids;  // user data: obstacle index as StaticMap::signed_distance
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::shared_ptr<fcl::Sphered> probe_shape = std::make_shared<fcl::Sphered>(kProbe);

  void add(int id, double cx, double cy, double theta, double sx, double sy) {
    auto shape = std::make_shared<fcl::Boxd>(sx, sy, kHeight);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = fcl::Vector3d(cx, cy, 0.0);
    tf.linear() = fcl::AngleAxisd(theta, fcl::Vector3d::UnitZ()).toRotationMatrix();
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(shape, tf));
    ids.push_back(id);
  }
};

FclDistance::FclDistance(const StaticMap& map) : impl_(std::make_unique<Impl>()) {
  const double w = map.width(), h = map.height();
  impl_->ids.reserve(map.boxes().size() + 4);
  impl_->add(-1, -0.5 * kWall, 0.5 * h, 0.0, kWall, h + 2 * kWall);
  impl_->add(-2, w + 0.5 * kWall, 0.5 * h, 0.0, kWall, h + 2 * kWall);
  impl_->add(-3, 0.5 * w, -0.5 * kWall, 0.0, w + 2 * kWall, kWall);
  impl_->add(-4, 0.5 * w, h + 0.5 * kWall, 0.0, w + 2 * kWall, kWall);
  for (int i = 0; i < static_cast<int>(map.boxes().size()); ++i) {
    const MapBox& b = map.boxes()[i];
    impl_->add(i, b.center.x(), b.center.y(), std::atan2(b.s, b.c), 2 * b.half.x(), 2 * b.half.y());
  }
  // The ids vector is complete: user data pointers into it stay valid.
  for (std::size_t k = 0; k < impl_->objects.size(); ++k) {
    impl_->objects[k]->setUserData(&impl_->ids[k]);
    impl_->manager.registerObject(impl_->objects[k].get());
  }
  impl_->manager.setup();
}

FclDistance::~FclDistance() = default;

double FclDistance::distance(const Vec2& p, int* which) const {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation() = fcl::Vector3d(p.x(), p.y(), 0.0);
  fcl::CollisionObjectd probe(impl_->probe_shape, tf);
  Query q;
  q.probe = &probe;
  impl_->manager.distance(&probe, &q, on_pair);
  if (which) *which = q.which;
  return q.min <= 0.0 ? 0.0 : q.min + kProbe;
}

}  // namespace llsf::planner::detail
