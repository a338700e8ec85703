-- SPDX-License-Identifier: MIT
-- motor_move: a short relative move with the motor, closed-loop on the pose estimate.
name               = "motor_move"
fsm                = SkillHSM:new{name=name, start="MOVE"}
depends_skills     = nil
depends_interfaces = {
   {v = "motor", type = "MotorInterface", id = "Robotino"},
   {v = "pose",  type = "Position3DInterface", id = "Pose"},
}
documentation      = [==[Moves the robot relative to where it stands, without path planning
(for the last centimetres at a machine, or to back off). Holonomic: x, y and ori at once.
@param x          metres forward (negative: backwards; an assisted holder lets its puck go)
@param y          metres to the left
@param ori        radians to turn (counter-clockwise)
@param vel_trans  top speed (m/s, default 0.3)
@param vel_rot    top turn rate (rad/s, default 1.0)
@param tolerance  position tolerance (m, default 0.01; heading: 0.03 rad)
Fails: "motor_move: no progress for 2 s (blocked?)" when something holds the robot back,
"motor_move: not there after N s", "motor_move needs numbers x, y, ori". Without stuck
detection (profile.stuck_detection false, the robotino-2013 profile: the thesis' skills had
none) it neither checks progress nor gives up: a robot held back keeps trying.
With the profile's motions "carologistics-2013" (robotino-2013) it moves as the team's 2013
motor_move did (carologistics/fawkes-robotino 6cffc15f2, src/lua/skills/robotino/motor_move.lua):
each axis (x, y, ori) on its own, at most V_MAX 0.4 m/s and 2.2 rad/s (or vel_trans, vel_rot),
accelerating by 0.05 m/s (0.10 rad/s) a cycle, decelerating as V_MAX/D_DECEL/5 times the
distance left (D_DECEL 0.07 m, 0.2 rad), never slower than V_MIN 0.035 m/s (0.15 rad/s), and an
axis within its tolerance (0.04 m, 0.05 rad; `tolerance` replaces the metres) is not moved at
all: the move ends when no axis moves.
]==]

-- The team's motor_move (6cffc15f2): per-axis limits, tolerances and ramps.
local TEAM = {
   V_MAX = {x = 0.4, y = 0.4, ori = 2.2},
   V_MIN = {x = 0.035, y = 0.035, ori = 0.15},
   TOLERANCE = {x = 0.04, y = 0.04, ori = 0.05},
   D_DECEL = {x = 0.07, y = 0.07, ori = 0.2},
   ACCEL = {x = 0.05, y = 0.05, ori = 0.10},
}

local function team() return profile.motions == "carologistics-2013" end

local function field_goal(vars)
   local x, y, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   local dx, dy = vars.x or 0, vars.y or 0
   return x + c * dx - s * dy, y + s * dx + c * dy, th + (vars.ori or 0)
end

local function norm_angle(a)
   while a > math.pi do a = a - 2 * math.pi end
   while a < -math.pi do a = a + 2 * math.pi end
   return a
end

-- Error to the goal in the robot frame: ex, ey, etheta, distance.
local function errors(vars)
   local x, y, th = pose:get()
   local gx, gy = vars.gx - x, vars.gy - y
   local c, s = math.cos(th), math.sin(th)
   local ex, ey = c * gx + s * gy, -s * gx + c * gy
   return ex, ey, norm_angle(vars.gth - th), math.sqrt(ex * ex + ey * ey)
end

local function bad_args(self, vars)
   for _, k in ipairs{"x", "y", "ori", "vel_trans", "vel_rot", "tolerance"} do
      if vars[k] ~= nil and type(vars[k]) ~= "number" then return true end
   end
   return false
end

-- The team's velocities for the errors (ex, ey, et): 0 on an axis within its tolerance.
local function team_speeds(vars, ex, ey, et)
   local d = {x = ex, y = ey, ori = et}
   local out = {}
   for _, k in ipairs{"x", "y", "ori"} do
      local tol = TEAM.TOLERANCE[k]
      if k ~= "ori" and vars.tolerance then tol = vars.tolerance end
      if math.abs(d[k]) > tol then
         local v_acc = vars.cycle * TEAM.ACCEL[k]
         local v_dec = TEAM.V_MAX[k] / TEAM.D_DECEL[k] / 5 * math.abs(d[k])
         local vmax = (k == "ori") and vars.wmax or vars.vmax
         local v = math.min(vmax, math.max(TEAM.V_MIN[k], math.min(TEAM.V_MAX[k], v_acc, v_dec)))
         out[k] = d[k] < 0 and -v or v
      else
         out[k] = 0
      end
   end
   return out.x, out.y, out.ori
end

local function there(self, vars)
   local ex, ey, et, d = errors(vars)
   if team() then
      local vx, vy, w = team_speeds(vars, ex, ey, et)
      return vx == 0 and vy == 0 and w == 0
   end
   return d <= vars.tol and math.abs(et) <= 0.03
end

local function stalled(self, vars)
   if not profile.stuck_detection then return false end
   local now = clock.now()
   local _, _, et, d = errors(vars)
   local progress = d + 0.2 * math.abs(et)
   if progress < vars.best - 0.005 then
      vars.best, vars.best_at = progress, now
      return false
   end
   if now - vars.best_at >= 2.0 then
      self.fsm.error = "motor_move: no progress for 2 s (blocked?)"
      return true
   end
   return false
end

local function timed_out(self, vars)
   if not profile.stuck_detection or clock.now() < vars.deadline then return false end
   self.fsm.error = string.format("motor_move: not there after %.0f s", vars.limit)
   return true
end

fsm:define_states{ export_to=_M,
   {"MOVE", JumpState},
}

fsm:add_transitions{
   {"MOVE", "FAILED", precond=bad_args, error="motor_move needs numbers x, y, ori"},
   {"MOVE", "FINAL", cond=there, desc="there"},
   {"MOVE", "FAILED", cond=stalled, desc="no progress"},
   {"MOVE", "FAILED", cond=timed_out, desc="timeout"},
}

function MOVE:init()
   local v = self.fsm.vars
   v.gx, v.gy, v.gth = field_goal(v)
   v.tol = v.tolerance or 0.01
   v.vmax = v.vel_trans or (team() and TEAM.V_MAX.x or 0.3)
   v.wmax = v.vel_rot or (team() and TEAM.V_MAX.ori or 1.0)
   v.cycle = 0
   local _, _, et, d = errors(v)
   v.best, v.best_at = d + 0.2 * math.abs(et), clock.now()
   v.limit = 5 + 3 * (d / v.vmax + math.abs(et) / v.wmax)
   v.deadline = clock.now() + v.limit
end

function MOVE:loop()
   local v = self.fsm.vars
   local ex, ey, et, d = errors(v)
   if team() then
      v.cycle = v.cycle + 1
      motor:set_velocity(team_speeds(v, ex, ey, et))
      return
   end
   local speed = 0
   if d > v.tol * 0.5 then speed = math.min(v.vmax, math.max(0.04, 1.5 * d)) end
   local vx, vy = 0, 0
   if d > 1e-6 then vx, vy = speed * ex / d, speed * ey / d end
   local w = 0
   if math.abs(et) > 0.01 then
      w = math.min(v.wmax, math.max(0.15, 2.0 * math.abs(et)))
      if et < 0 then w = -w end
   end
   motor:set_velocity(vx, vy, w)
end

function MOVE:exit()
   motor:stop()
end
