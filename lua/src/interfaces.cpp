// SPDX-License-Identifier: MIT
// The robot interfaces skills declare in depends_interfaces (the simulated Fawkes blackboard),
// bound to RobotApi: every read goes to the robot at call time; commands take effect at once.
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine_impl.h"

namespace llsf::lua {

namespace {

using Impl = SkillEngine::Impl;

// Runs `f` (which pushes results and returns their count); a C++ exception from RobotApi becomes
// a Lua error at the calling skill's file:line (raised outside the catch block: no longjmp across
// a live exception).
template <class F>
int guarded(lua_State* L, F&& f) {
  Impl& e = Impl::of(L);
  int n = -1;
  try {
    n = f(e);
  } catch (const std::exception& ex) {
    e.cpp_error = ex.what();
  } catch (...) {
    e.cpp_error = "unknown C++ exception";
  }
  if (n < 0) return luaL_error(L, "robot: %s", e.cpp_error.c_str());
  return n;
}

const char* nav_status_name(NavStatus s) {
  switch (s) {
    case NavStatus::kIdle:
      return "IDLE";
    case NavStatus::kRunning:
      return "RUNNING";
    case NavStatus::kArrived:
      return "ARRIVED";
    case NavStatus::kNoPath:
      return "NO_PATH";
    case NavStatus::kInvalidGoal:
      return "INVALID_GOAL";
    case NavStatus::kBlocked:
      return "BLOCKED";
    case NavStatus::kStuck:
      return "STUCK";
    case NavStatus::kAborted:
      return "ABORTED";
  }
  return "?";
}

bool nav_failed(NavStatus s) {
  return s == NavStatus::kNoPath || s == NavStatus::kInvalidGoal || s == NavStatus::kBlocked ||
         s == NavStatus::kStuck || s == NavStatus::kAborted;
}

const char* lamp_name(Lamp l) {
  switch (l) {
    case Lamp::kOff:
      return "OFF";
    case Lamp::kOn:
      return "ON";
    case Lamp::kBlink:
      return "BLINKING";
  }
  return "?";
}

// ---- Position3DInterface (pose) ----
int pose_x(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.pose().pose.x);
    return 1;
  });
}
int pose_y(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.pose().pose.y);
    return 1;
  });
}
int pose_theta(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.pose().pose.theta);
    return 1;
  });
}
int pose_get(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const PoseEstimate p = e.robot.pose();
    lua_pushnumber(L, p.pose.x);
    lua_pushnumber(L, p.pose.y);
    lua_pushnumber(L, p.pose.theta);
    return 3;
  });
}
int pose_is_valid(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.pose().valid);
    return 1;
  });
}
int pose_stamp(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.pose().stamp.seconds());
    return 1;
  });
}
int pose_distance_to(lua_State* L) {
  const double x = luaL_checknumber(L, 2);
  const double y = luaL_checknumber(L, 3);
  return guarded(L, [&](Impl& e) {
    const PoseEstimate p = e.robot.pose();
    lua_pushnumber(L, std::hypot(p.pose.x - x, p.pose.y - y));
    return 1;
  });
}

// ---- NavigatorInterface (navigator) ----
int nav_goto_place(lua_State* L) {
  std::size_t n = 0;
  const char* place = luaL_checklstring(L, 2, &n);
  const bool forward = lua_toboolean(L, 3) != 0;
  return guarded(L, [&](Impl& e) {
    e.robot.goto_place(std::string_view(place, n), forward);
    return 0;
  });
}
int nav_goto_pose(lua_State* L) {
  const core::Pose2D goal{luaL_checknumber(L, 2), luaL_checknumber(L, 3),
                          luaL_optnumber(L, 4, 0.0)};
  const bool forward = lua_toboolean(L, 5) != 0;
  return guarded(L, [&](Impl& e) {
    e.robot.goto_pose(goal, forward);
    return 0;
  });
}
// navigator:place(name) -> x, y, theta, target_x, target_y (nothing for unknown names).
int nav_place(lua_State* L) {
  std::size_t n = 0;
  const char* place = luaL_checklstring(L, 2, &n);
  return guarded(L, [&](Impl& e) {
    const std::optional<PlaceInfo> p = e.robot.place(std::string_view(place, n));
    if (!p) return 0;
    lua_pushnumber(L, p->pose.x);
    lua_pushnumber(L, p->pose.y);
    lua_pushnumber(L, p->pose.theta);
    lua_pushnumber(L, p->target.x());
    lua_pushnumber(L, p->target.y());
    return 5;
  });
}

// ---- SymbolicInterface (sym) ----
int sym_active(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.symbolic() ? 1 : 0);
    return 1;
  });
}
// sym:travel(x, y [, theta]) -> seconds, length_m  |  nil, error
int sym_travel(lua_State* L) {
  const core::Pose2D goal{luaL_checknumber(L, 2), luaL_checknumber(L, 3),
                          luaL_optnumber(L, 4, 0.0)};
  return guarded(L, [&](Impl& e) {
    const TravelEstimate t = e.robot.symbolic_travel(goal);
    if (!t.ok) {
      lua_pushnil(L);
      lua_pushstring(L, t.error.c_str());
      return 2;
    }
    lua_pushnumber(L, t.seconds);
    lua_pushnumber(L, t.length_m);
    return 2;
  });
}
int sym_move(lua_State* L) {
  const core::Pose2D goal{luaL_checknumber(L, 2), luaL_checknumber(L, 3),
                          luaL_optnumber(L, 4, 0.0)};
  return guarded(L, [&](Impl& e) {
    e.robot.symbolic_move(goal);
    return 0;
  });
}
int sym_pick(lua_State* L) {
  const core::Vec2 p{luaL_checknumber(L, 2), luaL_checknumber(L, 3)};
  const double radius = luaL_optnumber(L, 4, 0.1);
  return guarded(L, [&](Impl& e) {
    e.robot.symbolic_pick(p, radius);
    return 0;
  });
}
int sym_drop(lua_State* L) {
  const core::Vec2 p{luaL_checknumber(L, 2), luaL_checknumber(L, 3)};
  return guarded(L, [&](Impl& e) {
    e.robot.symbolic_drop(p);
    return 0;
  });
}

int robot_stop(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    e.robot.stop();
    return 0;
  });
}
// Reads the navigator into the engine's cache and pushes one derived value.
template <class Push>
int nav_read(lua_State* L, Push&& push) {
  return guarded(L, [&](Impl& e) {
    e.nav = e.robot.navigator();
    return push(e.nav);
  });
}
int nav_status(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushstring(L, nav_status_name(s.status));
    return 1;
  });
}
int nav_arrived(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushboolean(L, s.status == NavStatus::kArrived);
    return 1;
  });
}
int nav_failed_fn(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushboolean(L, nav_failed(s.status));
    return 1;
  });
}
int nav_running(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushboolean(L, s.status == NavStatus::kRunning);
    return 1;
  });
}
int nav_is_final(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushboolean(L, s.status == NavStatus::kArrived || nav_failed(s.status));
    return 1;
  });
}
int nav_error_code(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushinteger(L, nav_failed(s.status) ? static_cast<lua_Integer>(s.status) : 0);
    return 1;
  });
}
int nav_error_message(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushlstring(L, s.error.data(), s.error.size());
    return 1;
  });
}
int nav_blocked_by(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushlstring(L, s.blocked_by.data(), s.blocked_by.size());
    return 1;
  });
}
int nav_msgid(lua_State* L) {
  return nav_read(L, [&](const NavState& s) {
    lua_pushinteger(L, static_cast<lua_Integer>(s.goal_id));
    return 1;
  });
}

// ---- MotorInterface (motor) ----
int motor_set_velocity(lua_State* L) {
  const double vx = luaL_checknumber(L, 2);
  const double vy = luaL_checknumber(L, 3);
  const double omega = luaL_checknumber(L, 4);
  return guarded(L, [&](Impl& e) {
    e.robot.set_velocity(vx, vy, omega);
    return 0;
  });
}

// ---- RobotinoSensorInterface (sensor) ----
int sensor_puck_in_holder(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.puck_in_holder());
    return 1;
  });
}
int sensor_ir_distance(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.ir_distance_m());
    return 1;
  });
}
int sensor_optical_left(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.optical().left);
    return 1;
  });
}
int sensor_optical_right(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.optical().right);
    return 1;
  });
}

// ---- RobotinoLightInterface (light) ----
template <class Push>
int light_read(lua_State* L, Push&& push) {
  return guarded(L, [&](Impl& e) {
    e.light = e.robot.light();
    return push(e, e.light);
  });
}
int light_red(lua_State* L) {
  return light_read(L, [&](Impl&, const LightReading& r) {
    lua_pushstring(L, lamp_name(r.red));
    return 1;
  });
}
int light_yellow(lua_State* L) {
  return light_read(L, [&](Impl&, const LightReading& r) {
    lua_pushstring(L, lamp_name(r.yellow));
    return 1;
  });
}
int light_green(lua_State* L) {
  return light_read(L, [&](Impl&, const LightReading& r) {
    lua_pushstring(L, lamp_name(r.green));
    return 1;
  });
}
int light_visible(lua_State* L) {
  return light_read(L, [&](Impl&, const LightReading& r) {
    lua_pushboolean(L, r.visible);
    return 1;
  });
}
int light_device(lua_State* L) {
  return light_read(L, [&](Impl&, const LightReading& r) {
    lua_pushlstring(L, r.device.data(), r.device.size());
    return 1;
  });
}
int light_stable_for(lua_State* L) {
  return light_read(L, [&](Impl& e, const LightReading& r) {
    lua_pushnumber(L, r.visible ? (e.robot.now() - r.stable_since).seconds() : 0.0);
    return 1;
  });
}

// ---- PuckVisionInterface (pucks) ----
int pucks_count(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushinteger(L, static_cast<lua_Integer>(e.robot.pucks().size()));
    return 1;
  });
}
int pucks_puck(lua_State* L) {
  const lua_Integer i = luaL_checkinteger(L, 2);
  return guarded(L, [&](Impl& e) {
    const auto pucks = e.robot.pucks();
    if (i < 1 || i > static_cast<lua_Integer>(pucks.size())) return 0;
    const core::Vec2& p = pucks[static_cast<std::size_t>(i - 1)].position;
    lua_pushnumber(L, p.x());
    lua_pushnumber(L, p.y());
    return 2;
  });
}
int pucks_nearest(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const auto pucks = e.robot.pucks();
    if (pucks.empty()) return 0;
    const PuckSighting* best = &pucks[0];
    for (const PuckSighting& p : pucks) {
      if (p.position.norm() < best->position.norm()) best = &p;
    }
    lua_pushnumber(L, best->position.x());
    lua_pushnumber(L, best->position.y());
    lua_pushnumber(L, best->position.norm());
    return 3;
  });
}

// ---- ColourPuckInterface (puck_detector): the hackathon's flashlight camera ----
void push_colour_puck(lua_State* L, const ColourPuckSighting& p) {
  lua_pushnumber(L, p.position.x());
  lua_pushnumber(L, p.position.y());
  lua_pushnumber(L, p.distance_m);
  lua_pushnumber(L, p.bearing_rad);
  lua_pushstring(L, p.colour.c_str());
}
/// Whether `colour` matches the filter at stack index `arg`: none/nil, a string or a list.
bool colour_matches(lua_State* L, int arg, const std::string& colour) {
  if (lua_isnoneornil(L, arg)) return true;
  if (lua_type(L, arg) == LUA_TSTRING) return colour == lua_tostring(L, arg);
  if (lua_type(L, arg) != LUA_TTABLE) return false;
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, arg));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, arg, i);
    const bool match = lua_type(L, -1) == LUA_TSTRING && colour == lua_tostring(L, -1);
    lua_pop(L, 1);
    if (match) return true;
  }
  return false;
}
int cpucks_available(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.rescue() != nullptr);
    return 1;
  });
}
int cpucks_count(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushinteger(L, static_cast<lua_Integer>(e.robot.colour_pucks().size()));
    return 1;
  });
}
int cpucks_puck(lua_State* L) {
  const lua_Integer i = luaL_checkinteger(L, 2);
  return guarded(L, [&](Impl& e) {
    const auto pucks = e.robot.colour_pucks();
    if (i < 1 || i > static_cast<lua_Integer>(pucks.size())) return 0;
    push_colour_puck(L, pucks[static_cast<std::size_t>(i - 1)]);
    return 5;
  });
}
int cpucks_list(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const auto pucks = e.robot.colour_pucks();
    lua_createtable(L, static_cast<int>(pucks.size()), 0);
    for (std::size_t i = 0; i < pucks.size(); ++i) {
      const ColourPuckSighting& p = pucks[i];
      lua_createtable(L, 0, 5);
      lua_pushnumber(L, p.position.x());
      lua_setfield(L, -2, "x");
      lua_pushnumber(L, p.position.y());
      lua_setfield(L, -2, "y");
      lua_pushnumber(L, p.distance_m);
      lua_setfield(L, -2, "distance");
      lua_pushnumber(L, p.bearing_rad);
      lua_setfield(L, -2, "bearing");
      lua_pushstring(L, p.colour.c_str());
      lua_setfield(L, -2, "colour");
      lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
    }
    return 1;
  });
}
int cpucks_nearest(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const ColourPuckSighting* best = nullptr;
    for (const ColourPuckSighting& p : e.robot.colour_pucks()) {
      if (!colour_matches(L, 2, p.colour)) continue;
      if (best == nullptr || p.distance_m < best->distance_m) best = &p;
    }
    if (best == nullptr) return 0;
    push_colour_puck(L, *best);
    return 5;
  });
}

// ---- RescueInterface (rescue): the hackathon's task ----
bool in_rect(const RescueInfo& r, const core::Vec2& p) {
  return p.x() >= r.safe_lo.x() && p.y() >= r.safe_lo.y() && p.x() <= r.safe_hi.x() &&
         p.y() <= r.safe_hi.y();
}
void push_string_list(lua_State* L, const std::vector<std::string>& v) {
  lua_createtable(L, static_cast<int>(v.size()), 0);
  for (std::size_t i = 0; i < v.size(); ++i) {
    lua_pushstring(L, v[i].c_str());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
}
bool contains(const std::vector<std::string>& v, const char* s) {
  for (const std::string& x : v) {
    if (x == s) return true;
  }
  return false;
}
int rescue_active(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushboolean(L, e.robot.rescue() != nullptr);
    return 1;
  });
}
int rescue_in_safe_area(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    lua_pushboolean(L, r != nullptr && in_rect(*r, e.robot.pose().pose.position()));
    return 1;
  });
}
int rescue_holder_in_safe_area(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    const bool in =
        r != nullptr &&
        in_rect(*r, e.robot.pose().pose.to_parent(core::Vec2(r->held_puck_offset_m, 0.0)));
    lua_pushboolean(L, in);
    return 1;
  });
}
int rescue_safe_area(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    if (r == nullptr) return 0;
    lua_pushnumber(L, r->safe_lo.x());
    lua_pushnumber(L, r->safe_lo.y());
    lua_pushnumber(L, r->safe_hi.x());
    lua_pushnumber(L, r->safe_hi.y());
    return 4;
  });
}
int rescue_safe_place(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    if (r == nullptr) return 0;
    lua_pushstring(L, r->safe_place.c_str());
    return 1;
  });
}
int rescue_counts(lua_State* L) {
  const char* colour = luaL_checkstring(L, 2);
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    lua_pushboolean(L, r != nullptr && contains(r->counted, colour));
    return 1;
  });
}
int rescue_is_decoy(lua_State* L) {
  const char* colour = luaL_checkstring(L, 2);
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    lua_pushboolean(L, r != nullptr && contains(r->decoys, colour));
    return 1;
  });
}
int rescue_colours(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    push_string_list(L, r != nullptr ? r->counted : std::vector<std::string>{});
    return 1;
  });
}
int rescue_decoys(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    const RescueInfo* r = e.robot.rescue();
    push_string_list(L, r != nullptr ? r->decoys : std::vector<std::string>{});
    return 1;
  });
}

// ---- Laser360Interface (laser) ----
int laser_num_beams(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushinteger(L, static_cast<lua_Integer>(e.robot.laser().ranges.size()));
    return 1;
  });
}
int laser_distances(lua_State* L) {
  const lua_Integer i = luaL_checkinteger(L, 2);
  return guarded(L, [&](Impl& e) {
    const LaserView v = e.robot.laser();
    if (i < 0 || i >= static_cast<lua_Integer>(v.ranges.size())) return 0;
    lua_pushnumber(L, v.ranges[static_cast<std::size_t>(i)]);
    return 1;
  });
}
int laser_angle(lua_State* L) {
  const lua_Integer i = luaL_checkinteger(L, 2);
  return guarded(L, [&](Impl& e) {
    const LaserView v = e.robot.laser();
    lua_pushnumber(L, v.angle_min_rad + static_cast<double>(i) * v.angle_increment_rad);
    return 1;
  });
}
int laser_min_distance(lua_State* L) {
  const double from = luaL_checknumber(L, 2);
  const double to = luaL_checknumber(L, 3);
  return guarded(L, [&](Impl& e) {
    const LaserView v = e.robot.laser();
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < v.ranges.size(); ++i) {
      const double a =
          core::normalize_angle(v.angle_min_rad + static_cast<double>(i) * v.angle_increment_rad);
      if (a >= from && a <= to && v.ranges[i] < best) best = v.ranges[i];
    }
    lua_pushnumber(L, best);
    return 1;
  });
}

// ---- clock (a global, no declaration needed) ----
int clock_now(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushnumber(L, e.robot.now().seconds());
    return 1;
  });
}
int clock_now_ns(lua_State* L) {
  return guarded(L, [&](Impl& e) {
    lua_pushinteger(L, static_cast<lua_Integer>(e.robot.now().ns()));
    return 1;
  });
}

int read_only(lua_State* L) { return luaL_error(L, "interfaces are read-only"); }

// Pushes an interface object: an empty table whose metatable serves `methods` and refuses writes.
void push_object(lua_State* L, const char* type, const luaL_Reg* methods,
                 void (*extra)(lua_State*) = nullptr) {
  lua_newtable(L);           // object
  lua_createtable(L, 0, 4);  // metatable
  lua_newtable(L);           // methods
  luaL_setfuncs(L, methods, 0);
  lua_pushstring(L, type);
  lua_setfield(L, -2, "type");
  if (extra != nullptr) extra(L);
  lua_setfield(L, -2, "__index");
  lua_pushcfunction(L, read_only);
  lua_setfield(L, -2, "__newindex");
  lua_pushboolean(L, 0);
  lua_setfield(L, -2, "__metatable");
  lua_setmetatable(L, -2);
}

void light_constants(lua_State* L) {
  for (const char* c : {"ON", "OFF", "BLINKING"}) {
    lua_pushstring(L, c);
    lua_setfield(L, -2, c);
  }
}

}  // namespace

namespace {

struct InterfaceEntry {
  const char* type;
  const luaL_Reg* methods;
  void (*extra)(lua_State*);
};

// Every interface type with its methods (the interface objects' metatables serve these).
std::span<const InterfaceEntry> interface_entries() {
  static const luaL_Reg pose[] = {{"x", pose_x},         {"y", pose_y},
                                  {"theta", pose_theta}, {"ori", pose_theta},
                                  {"get", pose_get},     {"is_valid", pose_is_valid},
                                  {"stamp", pose_stamp}, {"distance_to", pose_distance_to},
                                  {nullptr, nullptr}};
  static const luaL_Reg navigator[] = {
      {"goto_place", nav_goto_place}, {"goto_pose", nav_goto_pose},
      {"stop", robot_stop},           {"status", nav_status},
      {"arrived", nav_arrived},       {"failed", nav_failed_fn},
      {"running", nav_running},       {"is_final", nav_is_final},
      {"error_code", nav_error_code}, {"error_message", nav_error_message},
      {"blocked_by", nav_blocked_by}, {"msgid", nav_msgid},
      {"place", nav_place},           {nullptr, nullptr}};
  static const luaL_Reg motor[] = {
      {"set_velocity", motor_set_velocity}, {"stop", robot_stop}, {nullptr, nullptr}};
  static const luaL_Reg sensor[] = {{"puck_in_holder", sensor_puck_in_holder},
                                    {"ir_distance", sensor_ir_distance},
                                    {"optical_left", sensor_optical_left},
                                    {"optical_right", sensor_optical_right},
                                    {nullptr, nullptr}};
  static const luaL_Reg light[] = {{"red", light_red},       {"yellow", light_yellow},
                                   {"green", light_green},   {"visible", light_visible},
                                   {"device", light_device}, {"stable_for", light_stable_for},
                                   {nullptr, nullptr}};
  static const luaL_Reg pucks[] = {
      {"count", pucks_count}, {"puck", pucks_puck}, {"nearest", pucks_nearest}, {nullptr, nullptr}};
  static const luaL_Reg colour_pucks[] = {{"available", cpucks_available}, {"count", cpucks_count},
                                          {"puck", cpucks_puck},           {"list", cpucks_list},
                                          {"nearest", cpucks_nearest},     {nullptr, nullptr}};
  static const luaL_Reg rescue[] = {{"active", rescue_active},
                                    {"in_safe_area", rescue_in_safe_area},
                                    {"holder_in_safe_area", rescue_holder_in_safe_area},
                                    {"safe_area", rescue_safe_area},
                                    {"safe_place", rescue_safe_place},
                                    {"counts", rescue_counts},
                                    {"is_decoy", rescue_is_decoy},
                                    {"colours", rescue_colours},
                                    {"decoys", rescue_decoys},
                                    {nullptr, nullptr}};
  static const luaL_Reg laser[] = {{"num_beams", laser_num_beams},
                                   {"distances", laser_distances},
                                   {"angle", laser_angle},
                                   {"min_distance", laser_min_distance},
                                   {nullptr, nullptr}};
  static const luaL_Reg sym[] = {{"active", sym_active}, {"travel", sym_travel},
                                 {"move", sym_move},     {"pick", sym_pick},
                                 {"drop", sym_drop},     {nullptr, nullptr}};

  static const InterfaceEntry entries[] = {{"Position3DInterface", pose, nullptr},
                                           {"NavigatorInterface", navigator, nullptr},
                                           {"MotorInterface", motor, nullptr},
                                           {"RobotinoSensorInterface", sensor, nullptr},
                                           {"RobotinoLightInterface", light, light_constants},
                                           {"PuckVisionInterface", pucks, nullptr},
                                           {"Laser360Interface", laser, nullptr},
                                           {"ColourPuckInterface", colour_pucks, nullptr},
                                           {"RescueInterface", rescue, nullptr},
                                           {"SymbolicInterface", sym, nullptr}};
  return entries;
}

}  // namespace

std::vector<std::string> interface_method_names() {
  std::vector<std::string> out;
  for (const InterfaceEntry& en : interface_entries()) {
    for (const luaL_Reg* m = en.methods; m->name != nullptr; ++m) {
      if (std::find(out.begin(), out.end(), m->name) == out.end()) out.emplace_back(m->name);
    }
  }
  return out;
}

void push_interfaces(lua_State* L) {
  static const luaL_Reg clock[] = {
      {"now", clock_now}, {"now_ns", clock_now_ns}, {nullptr, nullptr}};
  // native (at -1).interfaces = {Type = object, ...}; native.interface_names = "A, B, ..."
  lua_newtable(L);
  std::string names;
  for (const InterfaceEntry& en : interface_entries()) {
    push_object(L, en.type, en.methods, en.extra);
    lua_setfield(L, -2, en.type);
    if (!names.empty()) names += ", ";
    names += en.type;
  }
  lua_setfield(L, -2, "interfaces");
  lua_pushstring(L, names.c_str());
  lua_setfield(L, -2, "interface_names");
  push_object(L, "Clock", clock);
  lua_setfield(L, -2, "clock");
}

}  // namespace llsf::lua
