-- SPDX-License-Identifier: MIT
-- Reference solution of exercises 03-bring-one-home, 04-rescue-5-minutes and 05-two-robots
-- (tests/app/exercise_test.cpp): one call brings one puck of a counted colour to the safe area.
-- It turns on the spot at lookouts along the lanes (two robots split them by robot_name),
-- takes a puck seen in a counted colour for 0.3 s, carries it to the safe place and leaves it.
-- Failures (a puck out of reach, a blocked path) are remembered and skipped, never fatal.
name               = "rescue"
fsm                = SkillHSM:new{name=name, start="LOOK"}
depends_skills     = {"drive_to", "take_puck", "leave_puck"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
   {v = "motor", type = "MotorInterface"},
   {v = "sensor", type = "RobotinoSensorInterface"},
   {v = "puck_detector", type = "ColourPuckInterface"},
   {v = "rescue", type = "RescueInterface"},
}
documentation      = [==[Brings one puck of a counted colour to the safe area.]==]

local ALL = {
   {1.12, 1.12}, {2.24, 1.12}, {3.36, 1.12}, {4.25, 0.85}, {5.05, 1.70},
   {4.48, 2.24}, {3.30, 2.10}, {2.24, 2.24}, {1.12, 2.24}, {0.60, 1.70},
   {1.12, 3.36}, {2.24, 3.36}, {3.36, 3.36}, {4.48, 3.36}, {5.05, 3.90},
   {4.48, 4.48}, {3.20, 4.40}, {2.24, 4.48}, {2.24, 5.25}, {0.85, 4.65},
}
-- Module state survives the calls of one game (the exercise calls the skill again after FINAL).
local lookouts = nil
local next_lookout = 0
local given_up = {}   -- {x, y} of pucks that could not be taken

local function my_lookouts()
   if lookouts then return lookouts end
   lookouts = {}
   -- robot1 the lower half (y < 2.8), robot2 the upper one; alone: all.
   local two = robot_name == "robot1" or robot_name == "robot2"
   for _, p in ipairs(ALL) do
      if robot_name == "robot1" and p[2] < 2.8 or robot_name == "robot2" and p[2] > 2.8 then
         lookouts[#lookouts + 1] = p
      end
   end
   if #lookouts == 0 or not two then lookouts = ALL end
   return lookouts
end

local function to_field(rx, ry)
   local x, y, th = pose:get()
   return x + math.cos(th) * rx - math.sin(th) * ry, y + math.sin(th) * rx + math.cos(th) * ry
end

local function wanted(fx, fy)
   local x0, y0, x1, y1 = rescue:safe_area()
   if fx > x0 - 0.15 and fx < x1 + 0.15 and fy > y0 - 0.15 and fy < y1 + 0.15 then return false end
   for _, g in ipairs(given_up) do
      if math.sqrt((fx - g[1]) ^ 2 + (fy - g[2]) ^ 2) < 0.2 then return false end
   end
   return true
end

-- True once a wanted puck was seen in a counted colour at the same spot for 0.3 s.
local function confirmed(self, vars)
   if sensor:puck_in_holder() then return false end
   local best, bx, by, bc = 0.15, nil, nil, nil
   for _, s in ipairs(puck_detector:list()) do
      local fx, fy = to_field(s.x, s.y)
      if vars.cx then
         local d = math.sqrt((fx - vars.cx) ^ 2 + (fy - vars.cy) ^ 2)
         if d < best then best, bx, by, bc = d, fx, fy, s.colour end
      elseif rescue:counts(s.colour) and wanted(fx, fy) then
         vars.cx, vars.cy, vars.since = fx, fy, clock.now()
         return false
      end
   end
   if not vars.cx or not bx then return false end
   if not rescue:counts(bc) then vars.cx = nil return false end
   vars.cx, vars.cy = bx, by
   if clock.now() - vars.since < 0.3 then return false end
   vars.px, vars.py, vars.cx = bx, by, nil
   return true
end

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
   {"NEXT", JumpState},
   {"GO", SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="NEXT"},
   {"TAKE", SkillJumpState, skills={{take_puck}}, final_to="CHECK", fail_to="GIVE_UP"},
   {"CHECK", JumpState},
   {"GIVE_UP", SkillJumpState, skills={{leave_puck}}, final_to="LOOK", fail_to="LOOK"},
   {"BRING", SkillJumpState, skills={{drive_to}}, final_to="LEAVE", fail_to="RETRY"},
   {"RETRY", JumpState},
   {"LEAVE", SkillJumpState, skills={{leave_puck}}, final_to="FINAL", fail_to="FINAL"},
}

fsm:add_transitions{
   -- Driving sweeps pucks into the passive holder now and then: check its colour.
   {"LOOK", "CHECK", cond="sensor:puck_in_holder()", desc="a puck in the holder"},
   {"GO", "CHECK", cond="sensor:puck_in_holder()", desc="a puck in the holder"},
   {"LOOK", "TAKE", cond=confirmed},
   {"LOOK", "NEXT", timeout=6.5},
   {"GO", "TAKE", cond=confirmed},
   {"NEXT", "GO", cond=true},
   {"CHECK", "GIVE_UP", cond="vars.bad >= 2", desc="a decoy in the holder"},
   {"CHECK", "BRING", timeout=0.5},
   {"RETRY", "BRING", cond="vars.tries < 4 and sensor:puck_in_holder()"},
   {"RETRY", "GIVE_UP", cond=true},
}

function LOOK:init() motor:set_velocity(0, 0, 1.0) end
function LOOK:exit() motor:stop() end

function NEXT:init()
   local l = my_lookouts()
   next_lookout = next_lookout % #l + 1
   self.fsm.vars.lookout = l[next_lookout]
end

function GO:init()
   local p = self.fsm.vars.lookout
   self.args["drive_to"] = {x = p[1], y = p[2]}
end

function TAKE:init()
   self.args["take_puck"] = {x = self.fsm.vars.px, y = self.fsm.vars.py}
end

-- The camera sees the held puck too (0.2225 m ahead): count frames of a decoy colour there.
function CHECK:init()
   local v = self.fsm.vars
   v.bad, v.seen_at = 0, -1
   v.px, v.py = to_field(0.2225, 0)   -- where it lies, should it be a decoy
end
function CHECK:loop()
   local v = self.fsm.vars
   for _, s in ipairs(puck_detector:list()) do
      if math.abs(s.x - 0.2225) < 0.06 and math.abs(s.y) < 0.06 and clock.now() - v.seen_at > 0.09 then
         v.seen_at = clock.now()
         if not rescue:counts(s.colour) then v.bad = v.bad + 1 end
      end
   end
end

function GIVE_UP:init()
   given_up[#given_up + 1] = {self.fsm.vars.px, self.fsm.vars.py}
   self.args["leave_puck"] = {distance = 0.3}
end

function BRING:init()
   self.fsm.vars.tries = (self.fsm.vars.tries or 0) + 1
   self.args["drive_to"] = {place = rescue:safe_place()}
end

function LEAVE:init() self.args["leave_puck"] = {distance = 0.3} end
