-- SPDX-License-Identifier: MIT
-- get_s0: take a raw puck (S0) from the input storage or the late-order slot.
name               = "get_s0"
fsm                = SkillHSM:new{name=name, start="GOTO"}
depends_skills     = {"drive_to", "take_puck", "motor_move"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "pose",      type = "Position3DInterface", id = "Pose"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "pucks",     type = "PuckVisionInterface", id = "Puck"},
}
documentation      = [==[Takes an S0 into the holder: drives in front of the input storage (or the
late-order slot), picks the nearest puck it sees there and takes it.
@param place  "INS" (default: the storage, starting at a pickup spot chosen by the robot's
              number and moving on to the next spot when it sees no puck), "INS_1".."INS_5"
              (that spot only) or "LATE_ORDER" (the late-order insertion slot)
Fails: "get_s0: already holding a puck" (at the start, or "... (picked up on the way to INS_2)"
when the robot arrives at the storage with a puck it swept up while driving), "get_s0: unknown
place 'X'", "get_s0: no puck seen at INS_2" (after every spot it may try), or take_puck's/
drive_to's failure after 4 attempts (a puck that could not be taken is not tried again, and one
left half in the holder is let go by backing off before the next attempt; a puck so deep in the
storage that the holder's arms would touch the wall -- pressed into it -- is not tried at all;
2013 field, 5.6 m square).
]==]

local LOOK_BACK = 0.45   -- the look position lies this far out from the pickup place
local HELD = 0.2225      -- robot centre to a held puck's centre
-- The holder's arms reach 0.25 m ahead of the robot centre (body radius 0.185 + arm 0.065): the
-- robot taking a puck must stand this far from every wall, or its arms meet the wall first.
local ARM_CLEAR = 0.255

local function spots(vars)
   if vars.place == nil or vars.place == "INS" then
      -- Start where this robot's number says, so that robots do not queue at one spot.
      local n = tonumber(string.match(robot_name, "(%d+)$")) or 1
      local list = {}
      for i = 0, 4 do list[#list + 1] = "INS_" .. ((2 * (n - 1) + i) % 5 + 1) end
      return list
   end
   return {vars.place}
end

local function bad_place(self, vars)
   if vars.place ~= nil and vars.place ~= "INS" and type(vars.place) == "string" and
      navigator:place(vars.place) == nil then
      self.fsm.error = string.format("get_s0: unknown place '%s'", vars.place)
      return true
   end
   if vars.place ~= nil and type(vars.place) ~= "string" then
      self.fsm.error = "get_s0: place must be a string"
      return true
   end
   return false
end

-- The candidate: the sighting nearest to the spot's target (the pucks in reach), within 0.35 m.
local function choose(vars)
   local x, y, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   local best, bx, by = 0.35, nil, nil
   for i = 1, pucks:count() do
      local rx, ry = pucks:puck(i)
      local fx, fy = x + c * rx - s * ry, y + s * rx + c * ry
      local d = math.sqrt((fx - vars.tx) ^ 2 + (fy - vars.ty) ^ 2)
      local avoided = false
      for _, a in ipairs(vars.avoid or {}) do
         if (fx - a[1]) ^ 2 + (fy - a[2]) ^ 2 < 0.04 ^ 2 then avoided = true end
      end
      -- The robot would stand 0.2225 m before the puck: keep its arms off the walls (a puck
      -- pushed into the storage's wall is left alone).
      local dist = math.sqrt(rx * rx + ry * ry)
      local sx = fx - (fx - x) / dist * HELD
      local sy = fy - (fy - y) / dist * HELD
      local clear = sx >= ARM_CLEAR and sy >= ARM_CLEAR and sx <= 5.6 - ARM_CLEAR and
                    sy <= 5.6 - ARM_CLEAR
      if rx > 0.1 and d < best and not avoided and clear then best, bx, by = d, fx, fy end
   end
   if not bx then return false end
   vars.px, vars.py = bx, by
   return true
end

local function no_puck(self, vars)
   if clock.now() < vars.look_until then return false end
   vars.spot = vars.spot + 1
   if vars.spot > #vars.spots then
      self.fsm.error = string.format("get_s0: no puck seen at %s", table.concat(vars.spots, ", "))
      self.fsm.reason = "not-found"  -- an empty storage: nothing wrong with the robot
      return true
   end
   return false
end

-- Arrived with a puck in the holder that the robot swept up on its way: nothing can be taken.
local function arrived_holding(self, vars)
   if not sensor:puck_in_holder() then return false end
   self.fsm.error = string.format("get_s0: already holding a puck (picked up on the way to %s)",
                                  vars.spots[vars.spot])
   return true
end

fsm:define_states{ export_to=_M,
   {"GOTO",  SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="FAILED"},
   {"LOOK",  JumpState},
   {"TAKE",  SkillJumpState, skills={{take_puck}}, final_to="FINAL", fail_to="RETRY"},
   {"RETRY", JumpState},
   {"LET_GO", SkillJumpState, skills={{motor_move}}, final_to="GOTO", fail_to="FAILED"},
}

fsm:add_transitions{
   {"GOTO", "FAILED", precond="sensor:puck_in_holder()", error="get_s0: already holding a puck"},
   {"GOTO", "FAILED", precond=bad_place, desc="bad place"},
   {"LOOK", "FAILED", precond=arrived_holding, desc="puck picked up on the way"},
   {"LOOK", "TAKE", cond=function(self, vars) return choose(vars) end, desc="puck seen"},
   {"LOOK", "FAILED", cond=no_puck, desc="no puck anywhere"},
   {"LOOK", "GOTO", cond="clock.now() >= vars.look_until", desc="next spot"},
   {"RETRY", "FAILED", cond="vars.attempts >= 4", desc="too many attempts"},
   {"RETRY", "LET_GO", cond="sensor:puck_in_holder()", desc="a puck half in the holder"},
   {"RETRY", "GOTO", cond=true, desc="again"},
}

function GOTO:init()
   local v = self.fsm.vars
   v.spots = v.spots or spots(v)
   v.spot = v.spot or 1
   v.attempts = v.attempts or 0
   local px, py, pth, tx, ty = navigator:place(v.spots[v.spot])
   v.tx, v.ty = tx, ty
   self.args["drive_to"] = {x = px - math.cos(pth) * LOOK_BACK, y = py - math.sin(pth) * LOOK_BACK,
                            ori = pth}
end

function LOOK:init()
   -- A vision camera needs a frame or two after stopping.
   self.fsm.vars.look_until = clock.now() + 0.5
end

function TAKE:init()
   local v = self.fsm.vars
   v.attempts = v.attempts + 1
   self.args["take_puck"] = {x = v.px, y = v.py}
end

function RETRY:init()
   local v = self.fsm.vars
   -- Do not try that puck again (it may be wedged between others).
   v.avoid = v.avoid or {}
   v.avoid[#v.avoid + 1] = {v.px, v.py}
   if v.attempts >= 4 then
      self.fsm.error = "get_s0: " .. tostring(self.fsm.states.TAKE.error or "take_puck failed")
      self.fsm.reason = self.fsm.states.TAKE.reason  -- take_puck's, if it gave one
   end
end

function LET_GO:init()
   -- Backwards: the holder lets the puck go (it stays where it is and is not tried again).
   self.args["motor_move"] = {x = -0.2, vel_trans = 0.25}
end
