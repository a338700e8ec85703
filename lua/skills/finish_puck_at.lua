-- SPDX-License-Identifier: MIT
-- finish_puck_at: bring the held puck under a machine's RFID reader and read the outcome.
name               = "finish_puck_at"
fsm                = SkillHSM:new{name=name, start="APPROACH"}
depends_skills     = {"drive_to", "motor_move", "leave_puck", "take_puck"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "pose",      type = "Position3DInterface", id = "Pose"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "light",     type = "RobotinoLightInterface", id = "Light"},
   {v = "pucks",     type = "PuckVisionInterface", id = "Puck"},
}
documentation      = [==[Brings the held puck into the RFID zone of a machine (production machine,
recycler or test station), watches the signal light until it settles and reports the outcome as
the skill's result:
  "DONE"     the machine processed the puck and shows green: the product (an S1, S2, P1..P3 or,
             at a recycler, an S0) is in the holder;
  "WAITING"  the machine took the puck as an intermediate input and waits for more (yellow): the
             puck is put down beside the machine (left, or right if a puck lies left) and the
             robot backs off with an empty holder.
@param place  the machine: "M1".."M10", "R1", "R2" or "TST"
@param settle seconds a final light must hold before it counts (default 0.5)
Fails: "finish_puck_at: no puck in the holder", "finish_puck_at: unknown place 'X'",
"M3 is down (red)", "M3 rejected the puck (yellow blinking: invalid input)", "M3 did not react
(the puck is not under its RFID reader?)", "M3: no final light within 90 s", "finish_puck_at:
lost the puck (...)", drive_to's or take_puck's failure.
A puck lost on the way (the holder feels none for 0.3 s; e.g. the navigator backed off) is
fetched again as the 2013 skill take_puck_to did (carologistics/fawkes-robotino 6cffc15f2,
src/lua/skills/robotino/take_puck_to.lua: stop, wait 3 s, fetch_puck, go on; at most 3 times):
the robot stops, waits 3 s, takes the nearest puck it sees within 0.5 m and drives on. The
0.5 m is this skill's own limit (take_puck_to's fetch_puck took any puck its omni-vision saw),
so that a robot does not cross the field for a stranger's puck. The puck stays in the holder unless the outcome was WAITING;
then (and after a failure at the machine) the robot backs off 5 cm slowly (the holder keeps
the puck below 0.02 m/s) so that it can turn away from the machine.
With the profile's motions "carologistics-2013" (robotino-2013) the robot, once at the reader,
checks its position with the two optical sensors at the holder's arm tips as the team's
move_under_rfid did (6cffc15f2, src/lua/skills/robotino/move_under_rfid.lua: CHECK_POSITION,
CORRECT_POSITION, CORRECT_SENSOR_DELAY): if the right sensor sees something it moves right at
0.03 m/s (at most 0.3 m) until the left one does, else if the left one sees something it moves
left until the right one does, then 0.045 m back; a wall within the sensors' range beside a
recycler misleads it (thesis §5.3.2). It leaves a recycler
with its S0 as the team's 2013 skill did (finish_puck_at.lua -> leave_area_recycle.lua at
6cffc15f2): turn 45 degrees left, drive 0.4 m to the left, turn round (1.2 rad/s), 0.2 m on --
motor moves that, without stuck detection, push against whatever is in the way for good.
]==]

local machine_front = require("machine_front")

local PRE = 0.30          -- the approach stops this far before the input place
local REACT_S = 6.0       -- processing must show within this time (vision adds a delay)
local LIMIT_S = 90.0      -- T3/T4 take up to 60 s
local LOST_WAIT_S = 3.0   -- take_puck_to: WAIT -> SKILL_FETCH_PUCK after timeout=3
local MAX_REFETCH = 3     -- take_puck_to: MAX_RETRIES = 3
local REFETCH_RADIUS = 0.5

local function bad(self, vars)
   if type(vars.place) ~= "string" then
      self.fsm.error = "finish_puck_at needs place=<machine>"
      return true
   end
   if navigator:place(vars.place .. "_input") == nil then
      self.fsm.error = string.format("finish_puck_at: unknown place '%s'", vars.place)
      return true
   end
   return false
end

-- True if a puck lies near field point (x, y).
local function puck_near(x, y)
   local rx, ry, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   for i = 1, pucks:count() do
      local px, py = pucks:puck(i)
      local fx, fy = rx + c * px - s * py, ry + s * px + c * py
      if (fx - x) ^ 2 + (fy - y) ^ 2 < 0.1 ^ 2 then return true end
   end
   return false
end

-- The light of the machine, as a short code ("GY" = green + yellow on, "Yb" = yellow blinking)
-- or nil if the robot does not see it.
local function lights(vars)
   if not light:visible() or light:device() ~= vars.place then return nil end
   local function lamp(v, ch)
      if v == light.ON then return ch elseif v == light.BLINKING then return ch:lower() end
      return ""
   end
   return lamp(light:red(), "R") .. lamp(light:yellow(), "Y") .. lamp(light:green(), "G")
end

-- Watches the light; sets vars.outcome once it settles.
local function watch(self, vars)
   local code = lights(vars)
   local now = clock.now()
   if code == "YG" then vars.processing = true end
   local settled = code ~= nil and light:stable_for() >= (vars.settle or 0.5)
   if code ~= nil and string.find(code, "y") and light:stable_for() >= 0.6 then
      vars.fail = vars.place .. " rejected the puck (yellow blinking: invalid input)"
      return true
   end
   if settled and code == "R" then
      vars.fail = vars.place .. " is down (red)"
      return true
   end
   if vars.processing and settled and code == "G" then
      vars.outcome = "DONE"
      return true
   end
   if vars.processing and settled and code == "Y" then
      vars.outcome = "WAITING"
      return true
   end
   if not vars.processing and now - vars.arrived >= REACT_S then
      vars.fail = vars.place .. " did not react (the puck is not under its RFID reader?)"
      return true
   end
   if now - vars.arrived >= LIMIT_S then
      vars.fail = string.format("%s: no final light within %.0f s", vars.place, LIMIT_S)
      return true
   end
   return false
end

-- True once the holder has felt no puck for 0.3 s.
local function gone(vars)
   if sensor:puck_in_holder() then
      vars.lost_since = nil
      return false
   end
   vars.lost_since = vars.lost_since or clock.now()
   return clock.now() - vars.lost_since >= 0.3
end

-- Lost at the machine (the light is watched): a failure.
local function lost(self, vars)
   if not gone(vars) then return false end
   self.fsm.error = "finish_puck_at: lost the puck"
   return true
end

-- Lost on the way with tries left: fetch it again (LOST).
local function lost_on_way(self, vars)
   return (vars.refetches or 0) < MAX_REFETCH and gone(vars)
end

local function lost_for_good(self, vars)
   if (vars.refetches or 0) < MAX_REFETCH or not gone(vars) then return false end
   self.fsm.error = string.format("finish_puck_at: lost the puck (fetched again %d times)",
                                  MAX_REFETCH)
   return true
end

-- The nearest puck the robot sees within REFETCH_RADIUS (field x, y) or nil.
local function nearest_puck()
   local rx, ry, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   local best, bx, by = REFETCH_RADIUS, nil, nil
   for i = 1, pucks:count() do
      local px, py = pucks:puck(i)
      local d = math.sqrt(px * px + py * py)
      if d < best then best, bx, by = d, rx + c * px - s * py, ry + s * px + c * py end
   end
   return bx, by
end

-- After the wait: a puck to fetch?
local function refetch_found(self, vars)
   if clock.now() - vars.lost_at < LOST_WAIT_S then return false end
   vars.fetch_x, vars.fetch_y = nearest_puck()
   return vars.fetch_x ~= nil
end

local function nothing_to_fetch(self, vars)
   if clock.now() - vars.lost_at < LOST_WAIT_S then return false end
   self.fsm.error = string.format("finish_puck_at: lost the puck (none seen within %.1f m " ..
                                  "to fetch again)", REFETCH_RADIUS)
   return true
end

fsm:define_states{ export_to=_M,
   {"APPROACH", SkillJumpState, skills={{drive_to}}, final_to="LOOK_SIDES", fail_to="FAILED"},
   {"LOOK_SIDES", JumpState},
   {"INSERT",   SkillJumpState, skills={{drive_to}}, final_to="CHECK_POSITION",
    fail_to="FAILED"},
   -- carologistics-2013: move_under_rfid's correction on the optical sensors.
   {"CHECK_POSITION", JumpState},
   {"CORRECT_POSITION", SkillJumpState, skills={{motor_move}}, final_to="CORRECT_DELAY",
    fail_to="FAILED"},
   {"CORRECT_DELAY", SkillJumpState, skills={{motor_move}}, final_to="WAIT_LIGHT",
    fail_to="FAILED"},
   {"WAIT_LIGHT", JumpState},
   {"DECIDE",   JumpState},
   {"ASIDE",    SkillJumpState, skills={{motor_move}}, final_to="LEAVE", fail_to="FAILED"},
   -- Its own arguments: leave_puck must not take this skill's place (it would read it as where to
   -- carry the puck); the puck stays beside the machine.
   {"LEAVE",    SkillJumpState, skills={{leave_puck, distance=0.25}}, final_to="FINAL",
    fail_to="FAILED"},
   -- Keeping the puck: back off a few cm slowly enough for the holder to keep it, so that the
   -- robot can turn away from the machine face with the puck.
   {"CLEAR",    SkillJumpState, skills={{motor_move}}, final_to="CLEARED", fail_to="CLEARED"},
   {"CLEARED",  JumpState},
   -- carologistics-2013: leave_area_recycle's four motor moves.
   {"RECYCLE_TURN",  SkillJumpState, skills={{motor_move}}, final_to="RECYCLE_LEFT",
    fail_to="FAILED"},
   {"RECYCLE_LEFT",  SkillJumpState, skills={{motor_move}}, final_to="RECYCLE_UTURN",
    fail_to="FAILED"},
   {"RECYCLE_UTURN", SkillJumpState, skills={{motor_move}}, final_to="RECYCLE_ON",
    fail_to="FAILED"},
   {"RECYCLE_ON",    SkillJumpState, skills={{motor_move}}, final_to="FINAL", fail_to="FAILED"},
   -- A puck lost on the way: stand, then fetch it again and drive on (take_puck_to).
   {"LOST",     JumpState},
   {"REFETCH",  SkillJumpState, skills={{take_puck}}, final_to="APPROACH", fail_to="FAILED"},
}

fsm:add_transitions{
   {"APPROACH", "FAILED", precond=bad, desc="bad arguments"},
   {"APPROACH", "FAILED", precond="not sensor:puck_in_holder()",
    error="finish_puck_at: no puck in the holder"},
   {"LOOK_SIDES", "INSERT", timeout=0.3},
   {"CHECK_POSITION", "WAIT_LIGHT", cond="profile.motions ~= 'carologistics-2013'"},
   {"CHECK_POSITION", "WAIT_LIGHT", cond="vars.correct_dir == 0", desc="no sensor sees"},
   {"CHECK_POSITION", "CORRECT_POSITION", cond=true, desc="a sensor sees: correct"},
   {"CORRECT_POSITION", "CORRECT_DELAY", cond=function(self, vars)
      if vars.correct_dir == -1 then return sensor:optical_left() end
      return sensor:optical_right()
   end, desc="the other sensor sees"},
   {"WAIT_LIGHT", "DECIDE", cond=watch, desc="light settled"},
   {"WAIT_LIGHT", "FAILED", cond=lost, desc="puck lost"},
   {"DECIDE", "ASIDE", cond="vars.outcome == 'WAITING'", desc="waiting for more"},
   {"DECIDE", "CLEAR", cond=true, desc="done or failed: keep the puck"},
   {"CLEARED", "RECYCLE_TURN", cond=function(self, vars)
      return vars.outcome == "DONE" and profile.motions == "carologistics-2013"
         and (vars.place == "R1" or vars.place == "R2")
   end, desc="done at a recycler: leave_area_recycle"},
   {"CLEARED", "FINAL", cond="vars.outcome == 'DONE'", desc="done"},
   {"CLEARED", "FAILED", cond=function(self, vars)
      self.fsm.error = vars.fail
      return true
   end, desc="failed"},
   {"APPROACH", "FAILED", cond=lost_for_good, desc="puck lost again"},
   {"APPROACH", "LOST", cond=lost_on_way, desc="puck lost"},
   {"INSERT", "FAILED", cond=lost_for_good, desc="puck lost again"},
   {"INSERT", "LOST", cond=lost_on_way, desc="puck lost"},
   {"LOST", "REFETCH", cond=refetch_found, desc="puck seen: fetch it"},
   {"LOST", "FAILED", cond=nothing_to_fetch, desc="no puck to fetch"},
}

function APPROACH:init()
   self.args["drive_to"] = machine_front.before_input(navigator, self.fsm.vars.place, PRE)
end

function LOST:init()
   self.fsm.vars.refetches = (self.fsm.vars.refetches or 0) + 1
   self.fsm.vars.lost_since = nil
   self.fsm.vars.lost_at = clock.now()
end

function REFETCH:init()
   self.args["take_puck"] = {x = self.fsm.vars.fetch_x, y = self.fsm.vars.fetch_y}
end

function LOOK_SIDES:exit()
   local v = self.fsm.vars
   local lx, ly = select(4, navigator:place(v.place .. "_left"))
   local rx, ry = select(4, navigator:place(v.place .. "_right"))
   v.left_busy = lx ~= nil and puck_near(lx, ly)
   v.right_busy = rx ~= nil and puck_near(rx, ry)
end

function INSERT:init()
   self.args["drive_to"] = {place = self.fsm.vars.place .. "_input", forward_only = true}
end

function CHECK_POSITION:init()
   local v = self.fsm.vars
   if sensor:optical_right() then
      v.correct_dir = -1
   elseif sensor:optical_left() then
      v.correct_dir = 1
   else
      v.correct_dir = 0
   end
end

function CORRECT_POSITION:init()
   self.args["motor_move"] = {y = self.fsm.vars.correct_dir * 0.3, vel_trans = 0.03}
end

function CORRECT_DELAY:init()
   self.args["motor_move"] = {y = -self.fsm.vars.correct_dir * 0.045}
end

function WAIT_LIGHT:init()
   self.fsm.vars.arrived = clock.now()
   self.fsm.vars.processing = false
   self.fsm.vars.outcome, self.fsm.vars.fail = nil, nil
end

function DECIDE:init()
   if self.fsm.vars.outcome then self.fsm.result = self.fsm.vars.outcome end
end

function RECYCLE_TURN:init()
   self.args["motor_move"] = {ori = math.pi / 4}
end

function RECYCLE_LEFT:init()
   self.args["motor_move"] = {y = 0.4}
end

function RECYCLE_UTURN:init()
   self.args["motor_move"] = {ori = math.pi, vel_rot = 1.2}
end

function RECYCLE_ON:init()
   self.args["motor_move"] = {x = 0.2}
end

function CLEAR:init()
   self.args["motor_move"] = {x = -0.05, vel_trans = 0.015, tolerance = 0.01}
end

function ASIDE:init()
   local v = self.fsm.vars
   -- Beside the reader, where the intermediate inputs lie (the <M>_left / <M>_right spots).
   local side = 0.22
   if v.left_busy and not v.right_busy then side = -0.22 end
   self.args["motor_move"] = {y = side, vel_trans = 0.2}
end
