-- SPDX-License-Identifier: MIT
-- take_puck: drive onto a puck lying on the field so that it ends in the holder.
name               = "take_puck"
fsm                = SkillHSM:new{name=name, start="APPROACH"}
depends_skills     = {"drive_to", "motor_move"}
depends_interfaces = {
   {v = "motor",  type = "MotorInterface", id = "Robotino"},
   {v = "pose",   type = "Position3DInterface", id = "Pose"},
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "pucks",  type = "PuckVisionInterface", id = "Puck"},
}
documentation      = [==[Takes the puck lying at a field position into the holder: drives to a
point in front of it, re-measures it with the puck detection, then creeps onto it until the IR
sensor feels it at the body.
@param x, y  field position of the puck (metres)
@param ori   heading to approach it with (rad; default: from where the robot stands)
With the profile's motions "carologistics-2013" (robotino-2013) a puck within 0.5 m is taken as
the team's 2013 fetch_puck took it (carologistics/fawkes-robotino 6cffc15f2,
src/lua/skills/robotino/fetch_puck.lua: TURN_TO_PUCK, then GRAB): the robot turns on the spot to
face it and creeps straight on, with no drive to a point in front of it -- so a puck lying beside
the holder is pushed away by the turning robot (thesis §6.1.3) and then not seen where expected.
Fails: "take_puck needs x=, y=", "take_puck: already holding a puck", drive_to's failure,
"take_puck: the puck is gone (not seen where expected)", "take_puck: blocked 0.03 m before the
puck (...)" (no progress for 1.5 s), "take_puck: did not reach the puck within 6 s (...)",
"take_puck: the puck did not stay in the holder".
]==]

local OFFSET = 0.2225   -- robot centre to a held puck's centre
local STANDOFF = 0.15   -- from the pre-position to the final pose
local TEAM_REACH = 0.5  -- carologistics-2013: a puck this near is turned to, not driven to

local function bad_args(self, vars)
   return type(vars.x) ~= "number" or type(vars.y) ~= "number"
end

-- Robot-frame position of a field point.
local function to_robot(px, py)
   local x, y, th = pose:get()
   local dx, dy = px - x, py - y
   local c, s = math.cos(th), math.sin(th)
   return c * dx + s * dy, -s * dx + c * dy
end

-- carologistics-2013 motions and a puck within TEAM_REACH: turn to it on the spot (fetch_puck).
local function team_turn(self, vars)
   if profile.motions ~= "carologistics-2013" or bad_args(self, vars) then return false end
   local ex, ey = to_robot(vars.x, vars.y)
   return ex * ex + ey * ey <= TEAM_REACH * TEAM_REACH
end

local function heading(vars)
   return math.cos(vars.ori), math.sin(vars.ori)
end

-- The sighting nearest to where the puck should be; updates vars.x/y if one is within 8 cm.
local function remeasure(vars)
   local ex, ey = to_robot(vars.x, vars.y)
   local best, bx, by = 0.08, nil, nil
   for i = 1, pucks:count() do
      local sx, sy = pucks:puck(i)
      local d = math.sqrt((sx - ex) ^ 2 + (sy - ey) ^ 2)
      if d < best then best, bx, by = d, sx, sy end
   end
   if not bx then return false end
   local x, y, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   vars.x, vars.y = x + c * bx - s * by, y + s * bx + c * by
   return true
end

local function touching()
   return sensor:puck_in_holder() and sensor:ir_distance() <= 0.006
end

local function creep_failed(self, vars)
   local ex, ey = to_robot(vars.x, vars.y)
   local left = ex - OFFSET
   if left < vars.best_left - 0.005 then
      vars.best_left, vars.best_at = left, clock.now()
   elseif clock.now() - vars.best_at >= 1.5 then
      self.fsm.error = string.format("take_puck: blocked %.2f m before the puck (neighbouring " ..
                                     "pucks or a wall in the way?)", math.max(0, left))
      return true
   end
   if clock.now() - vars.creep_start < 6.0 then return false end
   local ex, ey = to_robot(vars.x, vars.y)
   self.fsm.error = string.format(
      "take_puck: did not reach the puck within 6 s (it is %.2f m ahead, %.2f m aside; IR %.3f m)",
      ex - OFFSET, ey, sensor:ir_distance())
   return true
end

fsm:define_states{ export_to=_M,
   {"APPROACH", SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="FAILED"},
   {"TURN",     SkillJumpState, skills={{motor_move}}, final_to="LOOK", fail_to="FAILED"},
   {"LOOK",     JumpState},
   {"CREEP",    JumpState},
   {"SETTLE",   JumpState},
}

fsm:add_transitions{
   {"APPROACH", "FAILED", precond=bad_args, error="take_puck needs x=, y="},
   {"APPROACH", "FAILED", precond="sensor:puck_in_holder()",
    error="take_puck: already holding a puck"},
   {"APPROACH", "TURN", precond=team_turn, desc="near: turn to it (carologistics-2013)"},
   {"LOOK", "CREEP", cond=function(self, vars) return remeasure(vars) end, desc="seen"},
   {"LOOK", "FAILED", timeout={1.0, error="take_puck: the puck is gone (not seen where expected)"}},
   {"CREEP", "SETTLE", cond=touching, desc="puck at the body"},
   {"CREEP", "SETTLE", cond="vars.overshoot", desc="passed the puck"},
   {"CREEP", "FAILED", cond=creep_failed, desc="timeout"},
   {"SETTLE", "FINAL", cond="clock.now() >= vars.settle_until and sensor:puck_in_holder()",
    desc="held"},
   {"SETTLE", "FAILED", cond="clock.now() >= vars.settle_until",
    error="take_puck: the puck did not stay in the holder"},
}

function APPROACH:init()
   local v = self.fsm.vars
   if v.ori == nil then
      local x, y = pose:get()
      v.ori = math.atan(v.y - y, v.x - x)
   end
   local c, s = heading(v)
   local d = OFFSET + STANDOFF
   self.args["drive_to"] = {x = v.x - c * d, y = v.y - s * d, ori = v.ori, forward_only = true}
end

function TURN:init()
   local ex, ey = to_robot(self.fsm.vars.x, self.fsm.vars.y)
   self.args["motor_move"] = {ori = math.atan(ey, ex)}
end

function CREEP:init()
   local v = self.fsm.vars
   v.creep_start = clock.now()
   v.overshoot = false
   v.best_left, v.best_at = math.huge, clock.now()
end

function CREEP:loop()
   local v = self.fsm.vars
   -- Where the robot centre must end: OFFSET behind the puck, facing it.
   local ex, ey = to_robot(v.x, v.y)
   ex = ex - OFFSET
   if ex < -0.02 then v.overshoot = true end
   local vx = math.min(0.12, math.max(0.03, 1.2 * ex + 0.03))
   local vy = math.max(-0.1, math.min(0.1, 2.0 * ey))
   local _, _, th = pose:get()
   local bearing = math.atan(v.y - select(2, pose:get()), v.x - select(1, pose:get()))
   local et = bearing - th
   while et > math.pi do et = et - 2 * math.pi end
   while et < -math.pi do et = et + 2 * math.pi end
   motor:set_velocity(vx, vy, math.max(-0.5, math.min(0.5, 2.0 * et)))
end

function CREEP:exit()
   motor:stop()
end

function SETTLE:init()
   self.fsm.vars.settle_until = clock.now() + 0.2
end
