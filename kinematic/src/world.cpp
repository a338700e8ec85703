// SPDX-License-Identifier: MIT
// The kinematic world on Box2D 2.4. Outline of a step (World::step):
//   1. motor commands: clamp to limits, ramp within acceleration limits, set body velocities;
//      an assisted holder lets its puck go when the robot backs away;
//   2. Box2D step (contacts reported into the event list by the contact listener);
//   3. assisted holders take a puck seated in their pocket;
//   4. RFID zones: awake pucks are re-checked, changes become entered/left events;
//   5. sensors: odometry integrates every step; each sensor samples when its period is due.
#include "llsf/kinematic/world.h"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <unordered_map>

#include "llsf/core/assert.h"
#include "llsf/core/error.h"
#include "raycast.h"

// Box2D 2.4.1 times the phases of every b2World::Step (collide, solve, each island's init,
// velocity and position passes, TOI) with gettimeofday() for b2World::GetProfile(), which
// llsfsim never reads: about 20 wall-clock reads per step, 3 % of the CPU time of a
// move_base-2013 game (docs/benchmarks.md, "game_move_base"). Debian's libbox2d calls b2Timer's
// members through its procedure linkage table, so these definitions in the program take the
// place of the library's: the timer reads no clock and shows 0 ms. (A wall-clock read has no
// place in a deterministic step anyway; nothing else of Box2D changes.)
b2Timer::b2Timer() { Reset(); }
void b2Timer::Reset() {
  m_start_sec = 0;
  m_start_usec = 0;
}
float b2Timer::GetMilliseconds() const { return 0.0f; }

namespace llsf::kinematic {

using core::SimTime;

namespace {

constexpr double kGravity = 9.81;
// Box2D's collision skin around polygons (b2_polygonRadius); shapes are built that much smaller.
constexpr double kSkin = b2_polygonRadius;

// Collision categories.
constexpr std::uint16_t kCatWall = 0x1;
constexpr std::uint16_t kCatDevice = 0x2;
constexpr std::uint16_t kCatRobot = 0x4;
constexpr std::uint16_t kCatHolder = 0x8;
constexpr std::uint16_t kCatPuck = 0x10;

// Fixture user data: what a fixture belongs to, packed as (kind << 24) | index.
enum class Owner : std::uintptr_t {
  kWall = 1,
  kDevice = 2,
  kRobotBody = 3,
  kRobotHolder = 4,
  kPuck = 5
};
std::uintptr_t tag(Owner o, int index) {
  return (static_cast<std::uintptr_t>(o) << 24) | static_cast<std::uintptr_t>(index);
}
Owner owner_of(b2Fixture* f) { return static_cast<Owner>(f->GetUserData().pointer >> 24); }
int index_of(b2Fixture* f) { return static_cast<int>(f->GetUserData().pointer & 0xffffff); }

b2Vec2 to_b2(const Vec2& v) { return b2Vec2(static_cast<float>(v.x()), static_cast<float>(v.y())); }
Vec2 from_b2(const b2Vec2& v) { return Vec2(v.x, v.y); }

// Moves `current` towards `target` by at most `max_delta` (vector norm).
Vec2 ramp(const Vec2& current, const Vec2& target, double max_delta) {
  const Vec2 d = target - current;
  const double n = d.norm();
  if (n <= max_delta) return target;
  return current + d * (max_delta / n);
}
double ramp(double current, double target, double max_delta) {
  return current + std::clamp(target - current, -max_delta, max_delta);
}

// A periodic sampler: due() once per period, on a fixed grid of simulated time.
struct Sampler {
  SimTime period;
  SimTime next;
  bool due(SimTime now) {
    if (now < next) return false;
    next += period;
    if (next <= now) next = now + period;  // never fall behind by more than one period
    return true;
  }
};

}  // namespace

// ------------------------------------------------------------------------------------------------
struct World::Impl : public b2ContactListener {
  struct Robot {
    std::string name;
    b2Body* body = nullptr;
    MotorCommand command;    // as given, robot frame
    Vec2 wheel_v{0.0, 0.0};  // after clamping and ramping, robot frame
    double wheel_omega = 0.0;
    b2Joint* hold_joint = nullptr;  // assisted holder's grip
    int held_puck = -1;             // puck index while gripped
    int released_puck = -1;         // not re-gripped until it leaves the pocket
    // odometry
    Pose2D odom_pose;
    double odom_dist = 0.0, odom_rot = 0.0, odom_dv = 0.0, odom_domega = 0.0;
    core::RandomStream odom_rng, gyro_rng, ir_rng, optical_rng, laser_rng;
    Sampler odom_s, gyro_s, ir_s, optical_s, truth_s, laser_s;
    double gyro_yaw = 0.0;
    SimTime gyro_last;
    RobotSensors sensors;
  };
  struct Puck {
    PuckId id;
    b2Body* body = nullptr;
    int zone = -1;  // device index or -1
    bool removed = false;
  };

  WorldConfig cfg;
  b2World world{b2Vec2(0.0f, 0.0f)};
  b2Body* ground = nullptr;
  std::vector<Robot> robots;
  std::vector<Puck> pucks;
  std::vector<PuckId> puck_ids;
  /// Puck id -> index in `pucks` (ids are positive; the usual small ones in a flat table, the
  /// hot look-up of has_puck/puck_position, any other in the map).
  struct PuckIndex {
    static constexpr std::int32_t kFlat = 4096;
    std::vector<int> flat;
    std::unordered_map<std::int32_t, int> rest;
    /// The index, or -1.
    int find(std::int32_t id) const {
      if (id >= 0 && id < kFlat) {
        return id < static_cast<std::int32_t>(flat.size()) ? flat[static_cast<std::size_t>(id)]
                                                           : -1;
      }
      auto it = rest.find(id);
      return it == rest.end() ? -1 : it->second;
    }
    void insert(std::int32_t id, int index) {
      if (id >= 0 && id < kFlat) {
        if (id >= static_cast<std::int32_t>(flat.size()))
          flat.resize(static_cast<std::size_t>(id) + 1, -1);
        flat[static_cast<std::size_t>(id)] = index;
      } else {
        rest[id] = index;
      }
    }
  };
  PuckIndex puck_index;
  std::array<SignalLights, kDeviceCount> lights{};
  std::array<Vec2, kDeviceCount> zone_center{};
  std::array<double, kDeviceCount> zone_radius2{};
  SimTime now;
  float dt = 0.01f;
  WorldEvents events;
  RayCaster raycaster;
  RayCaster::ScanScratch scan_scratch;
  std::vector<double> noise_scratch;  // one scan's range noise
  std::vector<Circle> robot_circles;  // scratch, no per-step allocation
  std::vector<Circle> puck_circles;
  std::vector<Circle> other_circles;
  std::vector<Circle> near_robots;  // the optical sensors' candidates (update_sensors)
  std::vector<Circle> near_pucks;
  std::vector<int> near_faces;
  std::vector<int> pending_zone_check;  // pucks added/teleported/removed since the last step

  Impl(const WorldConfig& c, const core::Rng& rng) : cfg(c), raycaster(c) {
    dt = static_cast<float>(cfg.physics.step.seconds());
    world.SetAllowSleeping(true);  // 6x cheaper with resting pucks (measured)
    world.SetContactListener(this);
    build_static();
    for (const auto& p : cfg.pucks) add_puck(PuckId(p.id), p.position);
    for (int i = 0; i < static_cast<int>(cfg.robots.size()); ++i) add_robot(i, rng);
    events.rfid.reserve(64);
    events.collisions.reserve(64);
    robot_circles.reserve(cfg.robots.size());
    other_circles.reserve(cfg.robots.size());
    near_robots.reserve(cfg.robots.size());
    near_pucks.reserve(cfg.pucks.size() + 16);
    near_faces.reserve(static_cast<std::size_t>(raycaster.segment_count()));
    puck_circles.reserve(cfg.pucks.size() + 16);
    pending_zone_check.reserve(16);
    for (int d = 0; d < kDeviceCount; ++d) {
      zone_center[d] = cfg.devices[d].rfid_center();
      zone_radius2[d] = cfg.devices[d].rfid_radius_m * cfg.devices[d].rfid_radius_m;
    }
    // Initial zone membership is the state at t = 0, not an event.
    for (auto& p : pucks) p.zone = zone_of(from_b2(p.body->GetPosition()));
  }

  // Walls (outside the field) and device bodies, all on one static ground body.
  void build_static() {
    b2BodyDef def;
    ground = world.CreateBody(&def);
    const double w = cfg.field.width_m, h = cfg.field.height_m, t = cfg.field.wall_thickness_m;
    auto wall = [&](double cx, double cy, double hx, double hy) {
      b2PolygonShape s;
      s.SetAsBox(static_cast<float>(hx - kSkin), static_cast<float>(hy - kSkin), to_b2({cx, cy}),
                 0.0f);
      b2FixtureDef fd;
      fd.shape = &s;
      fd.friction = 0.3f;
      fd.filter.categoryBits = kCatWall;
      fd.userData.pointer = tag(Owner::kWall, 0);
      ground->CreateFixture(&fd);
    };
    wall(w / 2, -t / 2, w / 2 + t, t / 2);
    wall(w / 2, h + t / 2, w / 2 + t, t / 2);
    wall(-t / 2, h / 2, t / 2, h / 2 + t);
    wall(w + t / 2, h / 2, t / 2, h / 2 + t);
    for (int d = 0; d < kDeviceCount; ++d) {
      const core::OrientedBox box = cfg.devices[d].footprint();
      b2PolygonShape s;
      s.SetAsBox(static_cast<float>(std::max(box.half_extents.x() - kSkin, 0.001)),
                 static_cast<float>(std::max(box.half_extents.y() - kSkin, 0.001)),
                 to_b2(box.pose.position()), static_cast<float>(box.pose.theta));
      b2FixtureDef fd;
      fd.shape = &s;
      fd.friction = 0.3f;
      fd.filter.categoryBits = kCatDevice;
      fd.userData.pointer = tag(Owner::kDevice, d);
      ground->CreateFixture(&fd);
    }
    // Extra obstacles behave like walls (contacts count as robot-wall collisions).
    for (const ObstacleConfig& o : cfg.obstacles) {
      const core::OrientedBox box = o.footprint();
      b2PolygonShape s;
      s.SetAsBox(static_cast<float>(std::max(box.half_extents.x() - kSkin, 0.001)),
                 static_cast<float>(std::max(box.half_extents.y() - kSkin, 0.001)),
                 to_b2(box.pose.position()), static_cast<float>(box.pose.theta));
      b2FixtureDef fd;
      fd.shape = &s;
      fd.friction = 0.3f;
      fd.filter.categoryBits = kCatWall;
      fd.userData.pointer = tag(Owner::kWall, 0);
      ground->CreateFixture(&fd);
    }
  }

  void add_robot(int i, const core::Rng& rng) {
    const RobotStart& start = cfg.robots[i];
    const RobotModelConfig& m = cfg.robot;
    Robot r;
    r.name = start.name;
    b2BodyDef def;
    def.type = b2_dynamicBody;  // kinematic bodies would pass through walls
    def.position = to_b2(start.pose.position());
    def.angle = static_cast<float>(start.pose.theta);
    r.body = world.CreateBody(&def);
    const double area = core::kPi * m.radius_m * m.radius_m;
    b2CircleShape c;
    c.m_radius = static_cast<float>(m.radius_m);
    b2FixtureDef fd;
    fd.shape = &c;
    fd.density = static_cast<float>(m.mass_kg / area);
    fd.friction = static_cast<float>(m.contact_friction);
    fd.filter.categoryBits = kCatRobot;
    fd.userData.pointer = tag(Owner::kRobotBody, i);
    r.body->CreateFixture(&fd);
    // The holder's two arms: thin boxes left and right of the puck pocket.
    const HolderConfig& hc = m.holder;
    const double x0 = m.radius_m - 0.03, x1 = m.radius_m + hc.arm_length_m;
    // Box2D keeps a skin of b2_polygonRadius around polygons: shrink the core so that the
    // collision surface is where the config says (thin arms end up at least 2 skins thick).
    const double half_t = std::max(0.5 * hc.arm_thickness_m - kSkin, 0.0005);
    const double yc = 0.5 * hc.inner_width_m + kSkin + half_t;
    for (double side : {1.0, -1.0}) {
      b2PolygonShape arm;
      arm.SetAsBox(static_cast<float>(0.5 * (x1 - x0) - kSkin), static_cast<float>(half_t),
                   to_b2({0.5 * (x0 + x1), side * yc}), 0.0f);
      b2FixtureDef afd;
      afd.shape = &arm;
      afd.density = 0.0f;  // the body's mass is the robot's mass
      afd.friction = static_cast<float>(hc.arm_friction);
      afd.filter.categoryBits = kCatHolder;
      afd.userData.pointer = tag(Owner::kRobotHolder, i);
      r.body->CreateFixture(&afd);
    }
    r.odom_pose = start.pose;
    r.gyro_yaw = start.pose.theta;
    const std::string prefix = "kinematic/" + start.name + "/";
    r.odom_rng = rng.stream(prefix + "odometry");
    r.gyro_rng = rng.stream(prefix + "gyro");
    r.ir_rng = rng.stream(prefix + "ir");
    r.optical_rng = rng.stream(prefix + "optical");
    r.laser_rng = rng.stream(prefix + "laser");
    const SensorsConfig& sc = cfg.sensors;
    r.odom_s = {SimTime::period_of_hz(sc.odometry.rate_hz), SimTime()};
    r.gyro_s = {SimTime::period_of_hz(sc.gyro.rate_hz), SimTime()};
    r.ir_s = {SimTime::period_of_hz(sc.ir.rate_hz), SimTime()};
    r.optical_s = {SimTime::period_of_hz(sc.optical.rate_hz), SimTime()};
    r.truth_s = {SimTime::period_of_hz(sc.ground_truth.rate_hz), SimTime()};
    r.laser_s = {SimTime::period_of_hz(sc.laser.rate_hz), SimTime()};
    LaserScan& scan = r.sensors.laser;
    scan.angle_min_rad = -core::kPi;
    scan.angle_increment_rad = 2.0 * core::kPi / sc.laser.beams;
    scan.min_range_m = sc.laser.min_range_m;
    scan.max_range_m = sc.laser.max_range_m;
    scan.ranges.assign(static_cast<std::size_t>(sc.laser.beams),
                       std::numeric_limits<float>::infinity());
    robots.push_back(std::move(r));
  }

  void add_puck(PuckId id, const Vec2& pos) {
    if (id.value() <= 0)
      throw core::ConfigError("puck id must be > 0 (got " + std::to_string(id.value()) + ")");
    if (puck_index.find(id.value()) >= 0)
      throw core::ConfigError("puck " + std::to_string(id.value()) + " already exists");
    const PuckModelConfig& m = cfg.puck;
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position = to_b2(pos);
    def.linearDamping = 0.5f;  // air/rolling losses on top of Coulomb floor friction
    def.angularDamping = 2.0f;
    Puck p;
    p.id = id;
    p.body = world.CreateBody(&def);
    b2CircleShape c;
    c.m_radius = static_cast<float>(m.radius_m);
    b2FixtureDef fd;
    fd.shape = &c;
    fd.density = static_cast<float>(m.mass_kg / (core::kPi * m.radius_m * m.radius_m));
    fd.friction = static_cast<float>(m.contact_friction);
    fd.restitution = static_cast<float>(m.restitution);
    fd.filter.categoryBits = kCatPuck;
    const int index = static_cast<int>(pucks.size());
    fd.userData.pointer = tag(Owner::kPuck, index);
    p.body->CreateFixture(&fd);
    // Floor friction: a friction joint to the ground limits force and torque like Coulomb
    // friction (a constant deceleration of mu * g) instead of damping's exponential decay.
    b2FrictionJointDef fj;
    fj.Initialize(ground, p.body, p.body->GetWorldCenter());
    fj.maxForce = static_cast<float>(m.floor_friction * m.mass_kg * kGravity);
    fj.maxTorque =
        static_cast<float>(m.floor_friction * m.mass_kg * kGravity * m.radius_m * 2.0 / 3.0);
    world.CreateJoint(&fj);
    p.zone = -1;
    pucks.push_back(p);
    puck_ids.push_back(id);
    puck_index.insert(id.value(), index);
    pending_zone_check.push_back(index);
  }

  int puck_at(PuckId id) const {
    const int index = puck_index.find(id.value());
    if (index < 0 || pucks[static_cast<std::size_t>(index)].removed)
      throw core::ConfigError("unknown puck " + std::to_string(id.value()));
    return index;
  }
  const Robot& robot_at(RobotId id) const {
    LLSF_DEMAND_MSG(id.valid() && id.value() < static_cast<int>(robots.size()), "bad robot id");
    return robots[id.value()];
  }
  Robot& robot_at(RobotId id) {
    return const_cast<Robot&>(static_cast<const Impl*>(this)->robot_at(id));
  }

  int zone_of(const Vec2& p) const {
    for (int d = 0; d < kDeviceCount; ++d) {
      if ((p - zone_center[d]).squaredNorm() <= zone_radius2[d]) return d;
    }
    return -1;
  }

  // --- contact events -----------------------------------------------------------------------
  // A robot (body or holder arm) started touching a wall, a device or another robot. Several
  // fixture pairs of one encounter starting in the same step count once.
  static bool is_robot(Owner o) { return o == Owner::kRobotBody || o == Owner::kRobotHolder; }
  void BeginContact(b2Contact* contact) override {
    b2Fixture* a = contact->GetFixtureA();
    b2Fixture* b = contact->GetFixtureB();
    if (!is_robot(owner_of(a))) std::swap(a, b);
    if (!is_robot(owner_of(a))) return;
    CollisionEvent e;
    e.time = now;
    e.robot = RobotId(index_of(a));
    switch (owner_of(b)) {
      case Owner::kWall:
        e.kind = CollisionKind::kRobotWall;
        break;
      case Owner::kDevice:
        e.kind = CollisionKind::kRobotDevice;
        e.device = DeviceId(index_of(b));
        break;
      case Owner::kRobotBody:
      case Owner::kRobotHolder:
        e.kind = CollisionKind::kRobotRobot;
        e.other_robot = RobotId(index_of(b));
        if (e.other_robot < e.robot) std::swap(e.robot, e.other_robot);
        break;
      default:
        return;  // pucks are pushed, not collided with
    }
    for (const CollisionEvent& o : events.collisions) {
      if (o.kind == e.kind && o.robot == e.robot && o.other_robot == e.other_robot &&
          o.device == e.device && o.time == e.time)
        return;
    }
    events.collisions.push_back(e);
  }

  // --- the step -----------------------------------------------------------------------------
  void step() {
    events.rfid.clear();
    events.collisions.clear();
    const double h = dt;
    const RobotModelConfig& m = cfg.robot;
    now += cfg.physics.step;  // events of this step carry the time at its end

    // 1. motor commands
    for (auto& r : robots) {
      Vec2 target(r.command.vx_mps, r.command.vy_mps);
      const double speed = target.norm();
      if (speed > m.max_speed_mps) target *= m.max_speed_mps / speed;
      const double omega_target =
          std::clamp(r.command.omega_rps, -m.max_omega_rps, m.max_omega_rps);
      const Vec2 prev_v = r.wheel_v;
      const double prev_omega = r.wheel_omega;
      r.wheel_v = ramp(r.wheel_v, target, m.max_accel_mps2 * h);
      r.wheel_omega = ramp(r.wheel_omega, omega_target, m.max_alpha_rps2 * h);
      r.odom_dv += (r.wheel_v - prev_v).norm();
      r.odom_domega += std::abs(r.wheel_omega - prev_omega);
      if (r.hold_joint && r.command.vx_mps < -m.holder.release_backing_speed_mps) release(r);
      const float angle = r.body->GetAngle();
      const Vec2 vw = core::rotate(r.wheel_v, angle);
      r.body->SetLinearVelocity(to_b2(vw));
      r.body->SetAngularVelocity(static_cast<float>(r.wheel_omega));
      // Odometry counts what the wheels do, whether or not the robot moves.
      Pose2D& o = r.odom_pose;
      const Vec2 d = core::rotate(r.wheel_v, o.theta) * h;
      o.x += d.x();
      o.y += d.y();
      o.theta = core::normalize_angle(o.theta + r.wheel_omega * h);
      r.odom_dist += r.wheel_v.norm() * h;
      r.odom_rot += std::abs(r.wheel_omega) * h;
    }

    // 2. physics
    world.Step(dt, cfg.physics.velocity_iterations, cfg.physics.position_iterations);

    // 3. holders
    if (m.holder.mode == HolderMode::kAssisted) {
      for (auto& r : robots) update_holder(r);
    }

    // 4. RFID zones
    for (int i = 0; i < static_cast<int>(pucks.size()); ++i) {
      Puck& p = pucks[i];
      if (p.removed || !p.body->IsAwake()) continue;
      update_zone(i);
    }
    for (int i : pending_zone_check) update_zone(i);
    pending_zone_check.clear();

    // 5. sensors
    for (auto& r : robots) update_sensors(r);
  }

  void update_zone(int i) {
    Puck& p = pucks[i];
    const int z = p.removed ? -1 : zone_of(from_b2(p.body->GetPosition()));
    if (z == p.zone) return;
    if (p.zone >= 0) events.rfid.push_back({now, RfidEventKind::kLeft, p.id, DeviceId(p.zone)});
    if (z >= 0) events.rfid.push_back({now, RfidEventKind::kEntered, p.id, DeviceId(z)});
    p.zone = z;
  }

  // Is the puck (robot-frame centre `l`) between the arms? Seated = also touching the body.
  bool in_pocket(const Vec2& l) const {
    const HolderConfig& hc = cfg.robot.holder;
    return l.x() > cfg.robot.radius_m - 0.01 && l.x() < cfg.robot.radius_m + hc.arm_length_m &&
           std::abs(l.y()) < 0.5 * hc.inner_width_m;
  }
  bool seated(const Vec2& l) const {
    return in_pocket(l) && l.norm() < cfg.robot.radius_m + cfg.puck.radius_m + 0.01;
  }

  void update_holder(Robot& r) {
    const b2Transform& xf = r.body->GetTransform();
    const double reach = cfg.robot.radius_m + cfg.robot.holder.arm_length_m + 0.05;
    const double reach2 = reach * reach;
    if (r.released_puck >= 0) {
      const Puck& p = pucks[r.released_puck];
      if (p.removed || !in_pocket(from_b2(b2MulT(xf, p.body->GetPosition())))) r.released_puck = -1;
    }
    if (r.hold_joint) return;
    for (int i = 0; i < static_cast<int>(pucks.size()); ++i) {
      const Puck& p = pucks[i];
      if (p.removed || i == r.released_puck) continue;
      const b2Vec2 wp = p.body->GetPosition();
      if ((wp - xf.p).LengthSquared() > reach2) continue;
      if (!seated(from_b2(b2MulT(xf, wp)))) continue;
      if (r.command.vx_mps < -cfg.robot.holder.release_backing_speed_mps) continue;
      if (puck_held_by_other(i)) continue;
      b2WeldJointDef wj;
      wj.Initialize(r.body, p.body, wp);
      wj.collideConnected = false;
      r.hold_joint = world.CreateJoint(&wj);
      r.held_puck = i;
      return;
    }
  }
  bool puck_held_by_other(int puck) const {
    for (const auto& o : robots)
      if (o.held_puck == puck) return true;
    return false;
  }
  void release(Robot& r) {
    if (!r.hold_joint) return;
    world.DestroyJoint(r.hold_joint);
    r.hold_joint = nullptr;
    r.released_puck = r.held_puck;
    r.held_puck = -1;
  }

  // --- sensors ------------------------------------------------------------------------------
  void refresh_circles() {
    robot_circles.clear();
    const RobotModelConfig& m = cfg.robot;
    const double radius = m.laser_radius_m > 0.0 ? m.laser_radius_m : m.radius_m;
    for (int i = 0; i < static_cast<int>(robots.size()); ++i) {
      Vec2 centre = from_b2(robots[i].body->GetPosition());
      if (m.laser_offset_m != 0.0) {
        centre += core::rotate(Vec2(m.laser_offset_m, 0.0), robots[i].body->GetAngle());
      }
      robot_circles.push_back({centre, radius, i});
    }
    puck_circles.clear();
    for (int i = 0; i < static_cast<int>(pucks.size()); ++i)
      if (!pucks[i].removed)
        puck_circles.push_back({from_b2(pucks[i].body->GetPosition()), cfg.puck.radius_m, i});
  }
  std::span<const Circle> others(const Robot& self) {
    other_circles.clear();
    const int self_index = static_cast<int>(&self - robots.data());
    for (const Circle& c : robot_circles)
      if (c.index != self_index) other_circles.push_back(c);
    return other_circles;
  }

  // The other robots and the pucks that a ray starting within `reach_m` - range of the robot's
  // centre could hit within its range: the rest lie beyond every such ray's range, where a hit
  // counts as none, so a cast against these alone gives the same result (in the same order,
  // for the same ties) as one against all.
  void near_circles(const Robot& self, double reach_m) {
    const b2Vec2 c = self.body->GetPosition();
    const double cx = c.x, cy = c.y;
    const auto within = [cx, cy](const b2Vec2& q, double r2) {
      const double dx = double(q.x) - cx, dy = double(q.y) - cy;
      return dx * dx + dy * dy <= r2;
    };
    const double rr = reach_m + cfg.robot.radius_m + 1e-6, rp = reach_m + cfg.puck.radius_m + 1e-6;
    const double robot_r2 = rr * rr, puck_r2 = rp * rp;
    near_robots.clear();
    for (int i = 0; i < static_cast<int>(robots.size()); ++i) {
      if (&robots[i] == &self) continue;
      const b2Vec2& q = robots[i].body->GetPosition();
      if (within(q, robot_r2)) near_robots.push_back({from_b2(q), cfg.robot.radius_m, i});
    }
    near_pucks.clear();
    for (int i = 0; i < static_cast<int>(pucks.size()); ++i) {
      const Puck& p = pucks[i];
      if (p.removed) continue;
      const b2Vec2& q = p.body->GetPosition();
      if (within(q, puck_r2)) near_pucks.push_back({from_b2(q), cfg.puck.radius_m, i});
    }
  }

  void update_sensors(Robot& r) {
    const SensorsConfig& sc = cfg.sensors;
    RobotSensors& s = r.sensors;
    const Pose2D pose{r.body->GetPosition().x, r.body->GetPosition().y, r.body->GetAngle()};
    bool circles_fresh = false;
    auto need_circles = [&] {
      if (!circles_fresh) refresh_circles();
      circles_fresh = true;
    };

    if (r.odom_s.due(now)) {
      // The error grows with the square root of distance, rotation and velocity change, so that
      // it does not depend on the sampling rate; acceleration makes it grow faster.
      const OdometryConfig& oc = sc.odometry;
      const double st = std::sqrt(oc.trans_noise_per_m * oc.trans_noise_per_m * r.odom_dist +
                                  oc.accel_noise_per_mps * oc.accel_noise_per_mps * r.odom_dv);
      const double sr =
          std::sqrt(oc.rot_noise_per_rad * oc.rot_noise_per_rad * r.odom_rot +
                    oc.accel_rot_noise_per_rps * oc.accel_rot_noise_per_rps * r.odom_domega);
      if (st > 0.0) {
        const Vec2 e(r.odom_rng.normal(0.0, st), r.odom_rng.normal(0.0, st));
        const Vec2 ew = core::rotate(e, r.odom_pose.theta);
        r.odom_pose.x += ew.x();
        r.odom_pose.y += ew.y();
      }
      if (sr > 0.0)
        r.odom_pose.theta = core::normalize_angle(r.odom_pose.theta + r.odom_rng.normal(0.0, sr));
      r.odom_dist = r.odom_rot = r.odom_dv = r.odom_domega = 0.0;
      s.odometry.stamp = now;
      ++s.odometry.seq;
      s.odometry.pose = r.odom_pose;
      s.odometry.vx_mps = r.wheel_v.x();
      s.odometry.vy_mps = r.wheel_v.y();
      s.odometry.omega_rps = r.wheel_omega;
    }
    if (r.gyro_s.due(now)) {
      const GyroConfig& gc = sc.gyro;
      const double rate =
          r.body->GetAngularVelocity() + gc.bias_rps + r.gyro_rng.normal(0.0, gc.noise_std_rps);
      r.gyro_yaw = core::normalize_angle(r.gyro_yaw + rate * (now - r.gyro_last).seconds());
      r.gyro_last = now;
      s.gyro.stamp = now;
      ++s.gyro.seq;
      s.gyro.rate_rps = rate;
      s.gyro.yaw_rad = r.gyro_yaw;
    }
    if (r.ir_s.due(now)) {
      const IrConfig& ic = sc.ir;
      double d = ic.range_m;
      const b2Transform& xf = r.body->GetTransform();
      for (const Puck& p : pucks) {
        if (p.removed) continue;
        const Vec2 l = from_b2(b2MulT(xf, p.body->GetPosition()));
        if (!in_pocket(l)) continue;
        d = std::min(d, std::max(0.0, l.x() - cfg.puck.radius_m - cfg.robot.radius_m));
      }
      if (d < ic.range_m) d = std::clamp(d + r.ir_rng.normal(0.0, ic.noise_std_m), 0.0, ic.range_m);
      s.ir.stamp = now;
      ++s.ir.seq;
      s.ir.distance_m = d;
      s.ir.puck_detected = d < ic.threshold_m;
    }
    if (r.optical_s.due(now)) {
      const OpticalConfig& oc = sc.optical;
      const HolderConfig& hc = cfg.robot.holder;
      const double tip = cfg.robot.radius_m + hc.arm_length_m;
      const double yc = 0.5 * hc.inner_width_m + 0.5 * hc.arm_thickness_m;
      // Both rays start within `reach` - range of the robot's centre and share its heading.
      const double reach = Vec2(tip + 1e-4, yc).norm() + oc.range_m;
      near_circles(r, reach);
      raycaster.faces_near(pose.position(), reach, near_faces);
      const double dx = std::cos(pose.theta), dy = std::sin(pose.theta);
      auto fire = [&](double side) {
        const Vec2 o = pose.to_parent({tip + 1e-4, side * yc});
        const RayHit hit =
            raycaster.cast_among(o, dx, dy, oc.range_m, near_faces, near_robots, near_pucks);
        if (hit.kind == HitKind::kNone) return false;
        return !r.optical_rng.bernoulli(oc.miss_probability);
      };
      s.optical.stamp = now;
      ++s.optical.seq;
      s.optical.left = fire(1.0);
      s.optical.right = fire(-1.0);
    }
    if (r.truth_s.due(now)) {
      s.ground_truth.stamp = now;
      ++s.ground_truth.seq;
      s.ground_truth.pose = pose;
    }
    if (sc.laser.enabled && r.laser_s.due(now)) {
      need_circles();
      const LaserConfig& lc = sc.laser;
      LaserScan& scan = s.laser;
      const Vec2 origin = pose.to_parent({lc.mount_x_m, lc.mount_y_m});
      float* out = scan.ranges.data();
      const int n = static_cast<int>(scan.ranges.size());
      raycaster.scan(origin, pose.theta + scan.angle_min_rad, scan.angle_increment_rad, n,
                     lc.max_range_m, others(r), out, scan_scratch);
      const float lo = static_cast<float>(lc.min_range_m), hi = static_cast<float>(lc.max_range_m);
      // The noise of each beam that hit, drawn in beam order.
      int hits = 0;
      for (int i = 0; i < n; ++i) hits += std::isfinite(out[i]) ? 1 : 0;
      noise_scratch.resize(static_cast<std::size_t>(hits));
      r.laser_rng.normals(0.0, lc.noise_std_m, noise_scratch);
      const double* noise = noise_scratch.data();
      for (int i = 0; i < n; ++i) {
        if (!std::isfinite(out[i])) continue;
        const float v = out[i] + static_cast<float>(*noise++);
        out[i] = v > hi ? std::numeric_limits<float>::infinity() : std::max(v, lo);
      }
      scan.stamp = now;
      ++scan.seq;
    }
  }
};

namespace {
// Box2D 2.4 builds its table of contact types (b2Contact::s_registers) on the first contact of
// the process, unsynchronised. Two games starting at once on two threads would race on it: make
// one contact here, once per process under std::call_once, before any World builds its b2World:
// every World constructor calls it, so games may be built and stepped on any threads. (Its other
// globals, b2_gjkCalls and friends, are statistics counters nothing reads.)
void init_box2d_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    b2World world(b2Vec2(0.0f, 0.0f));
    b2CircleShape circle;
    circle.m_radius = 0.5f;
    b2BodyDef def;
    def.type = b2_dynamicBody;
    for (int i = 0; i < 2; ++i) world.CreateBody(&def)->CreateFixture(&circle, 1.0f);
    world.Step(0.01f, 1, 1);
  });
}
}  // namespace

// ------------------------------------------------------------------------------------------------
World::World(const WorldConfig& config, const core::Rng& rng) {
  config.validate();
  init_box2d_once();
  impl_ = std::make_unique<Impl>(config, rng);
}
World::~World() = default;

const WorldConfig& World::config() const { return impl_->cfg; }
SimTime World::time() const { return impl_->now; }
const WorldEvents& World::step() {
  impl_->step();
  return impl_->events;
}

int World::robot_count() const { return static_cast<int>(impl_->robots.size()); }
RobotId World::robot_by_name(std::string_view name) const {
  for (int i = 0; i < robot_count(); ++i)
    if (impl_->robots[i].name == name) return RobotId(i);
  return RobotId();
}
void World::set_command(RobotId robot, const MotorCommand& command) {
  LLSF_DEMAND(std::isfinite(command.vx_mps) && std::isfinite(command.vy_mps) &&
              std::isfinite(command.omega_rps));
  impl_->robot_at(robot).command = command;
}
Pose2D World::robot_pose(RobotId robot) const {
  const b2Body* b = impl_->robot_at(robot).body;
  return {b->GetPosition().x, b->GetPosition().y, core::normalize_angle(b->GetAngle())};
}
Vec2 World::robot_velocity(RobotId robot) const {
  return from_b2(impl_->robot_at(robot).body->GetLinearVelocity());
}
double World::robot_omega(RobotId robot) const {
  return impl_->robot_at(robot).body->GetAngularVelocity();
}
MotorCommand World::robot_wheel_velocity(RobotId robot) const {
  const auto& r = impl_->robot_at(robot);
  return {r.wheel_v.x(), r.wheel_v.y(), r.wheel_omega};
}
std::optional<PuckId> World::held_puck(RobotId robot) const {
  const auto& r = impl_->robot_at(robot);
  if (r.held_puck < 0) return std::nullopt;
  return impl_->pucks[r.held_puck].id;
}
void World::teleport_robot(RobotId robot, const Pose2D& pose) {
  auto& r = impl_->robot_at(robot);
  impl_->release(r);
  r.body->SetTransform(to_b2(pose.position()), static_cast<float>(pose.theta));
  r.body->SetLinearVelocity(b2Vec2(0, 0));
  r.body->SetAngularVelocity(0);
  r.body->SetAwake(true);
  r.wheel_v = Vec2(0, 0);
  r.wheel_omega = 0;
  r.command = MotorCommand{};
}
const RobotSensors& World::sensors(RobotId robot) const { return impl_->robot_at(robot).sensors; }

std::span<const PuckId> World::pucks() const { return impl_->puck_ids; }
bool World::has_puck(PuckId puck) const {
  const int index = impl_->puck_index.find(puck.value());
  return index >= 0 && !impl_->pucks[static_cast<std::size_t>(index)].removed;
}
Vec2 World::puck_position(PuckId puck) const {
  return from_b2(impl_->pucks[impl_->puck_at(puck)].body->GetPosition());
}
void World::puck_positions(std::vector<Vec2>& out) const {
  // `pucks` and `puck_ids` grow together; a removed puck leaves only `puck_ids`.
  for (const auto& p : impl_->pucks) {
    if (!p.removed) out.push_back(from_b2(p.body->GetPosition()));
  }
}
bool World::any_puck_within(const Vec2& point, double distance_m) const {
  for (const auto& p : impl_->pucks) {
    if (!p.removed && (from_b2(p.body->GetPosition()) - point).norm() < distance_m) return true;
  }
  return false;
}
Vec2 World::puck_velocity(PuckId puck) const {
  return from_b2(impl_->pucks[impl_->puck_at(puck)].body->GetLinearVelocity());
}
std::optional<DeviceId> World::puck_zone(PuckId puck) const {
  const int z = impl_->pucks[impl_->puck_at(puck)].zone;
  if (z < 0) return std::nullopt;
  return DeviceId(z);
}
std::vector<PuckId> World::pucks_in_zone(DeviceId device) const {
  std::vector<PuckId> out;
  for (const auto& p : impl_->pucks)
    if (!p.removed && p.zone == device.value()) out.push_back(p.id);
  return out;
}
void World::add_puck(PuckId puck, const Vec2& position) {
  const auto& f = impl_->cfg.field;
  if (!(position.x() > 0 && position.y() > 0 && position.x() < f.width_m &&
        position.y() < f.height_m))
    throw core::ConfigError("add_puck: position outside the field");
  if (has_puck(puck) || impl_->puck_index.find(puck.value()) >= 0)
    throw core::ConfigError("add_puck: puck " + std::to_string(puck.value()) + " already exists");
  impl_->add_puck(puck, position);
}
void World::remove_puck(PuckId puck) {
  const int i = impl_->puck_at(puck);
  for (auto& r : impl_->robots) {
    if (r.held_puck == i) impl_->release(r);
    if (r.released_puck == i) r.released_puck = -1;
  }
  auto& p = impl_->pucks[i];
  p.removed = true;
  p.body->SetEnabled(false);
  auto& ids = impl_->puck_ids;
  ids.erase(std::find(ids.begin(), ids.end(), puck));
  impl_->pending_zone_check.push_back(i);
}
void World::teleport_puck(PuckId puck, const Vec2& position) {
  const int i = impl_->puck_at(puck);
  for (auto& r : impl_->robots)
    if (r.held_puck == i) impl_->release(r);
  auto& p = impl_->pucks[i];
  p.body->SetTransform(to_b2(position), 0.0f);
  p.body->SetLinearVelocity(b2Vec2(0, 0));
  p.body->SetAngularVelocity(0);
  p.body->SetAwake(true);
  impl_->pending_zone_check.push_back(i);
}

void World::set_lights(DeviceId device, const SignalLights& lights) {
  LLSF_DEMAND(device.valid() && device.value() < kDeviceCount);
  impl_->lights[device.value()] = lights;
}
SignalLights World::lights(DeviceId device) const {
  LLSF_DEMAND(device.valid() && device.value() < kDeviceCount);
  return impl_->lights[device.value()];
}
std::span<const SignalLights, kDeviceCount> World::all_lights() const { return impl_->lights; }

std::uint64_t World::state_hash() const {
  std::uint64_t h = core::kFnvOffset;
  auto mix = [&h](const auto& v) { h = core::fnv1a(&v, sizeof(v), h); };
  mix(impl_->now.ns());
  auto body = [&](const b2Body* b) {
    mix(b->GetPosition().x);
    mix(b->GetPosition().y);
    mix(b->GetAngle());
    mix(b->GetLinearVelocity().x);
    mix(b->GetLinearVelocity().y);
    mix(b->GetAngularVelocity());
  };
  for (const auto& r : impl_->robots) {
    body(r.body);
    mix(r.odom_pose.x);
    mix(r.odom_pose.y);
    mix(r.odom_pose.theta);
    mix(r.gyro_yaw);
  }
  for (const auto& p : impl_->pucks) {
    mix(p.removed);
    if (!p.removed) body(p.body);
  }
  return h;
}

int World::awake_body_count() const {
  int n = 0;
  for (const b2Body* b = impl_->world.GetBodyList(); b; b = b->GetNext())
    if (b->GetType() != b2_staticBody && b->IsAwake() && b->IsEnabled()) ++n;
  return n;
}

}  // namespace llsf::kinematic
