-- SPDX-License-Identifier: MIT
-- get_consumed: pick up a consumed puck lying beside a machine.
name               = "get_consumed"
fsm                = SkillHSM:new{name=name, start="GOTO"}
depends_skills     = {"drive_to", "take_puck", "motor_move"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "pose",      type = "Position3DInterface", id = "Pose"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "pucks",     type = "PuckVisionInterface", id = "Puck"},
}
documentation      = [==[Takes a puck lying beside a machine (where finish_puck_at puts the
intermediate inputs, which the machine turns CONSUMED when it completes) into the holder.
@param place  the machine: "M1".."M10"
@param side   "left" or "right" to insist on one side (default: whichever has a puck, left first)
Fails: "get_consumed: already holding a puck", "get_consumed: unknown machine 'X'",
"get_consumed: no puck beside M3", take_puck's/drive_to's failure.
With the profile's motions "carologistics-2013" (robotino-2013) the robot moves as the team's
2013 get_consumed did (6cffc15f2, src/lua/skills/robotino/get_consumed.lua): from the look
position it drives to the machine's front (ADJUST_POS: 0.3 m before the input, facing it), moves
0.1 m on and 0.4 m sideways towards the puck's side while turning 0.3 rad back towards it
(DRIVE_TO_SIDE; the team always went right, here the side is the one the puck lies on, mirrored),
takes it turning to it first (fetch_puck), turns on the spot by 3.0 rad away from the machine
(LEAVE_TURN) and drives 0.5 m on (LEAVE_FORWARD) -- motor moves that, without stuck detection,
push against whatever is in the way for good.
]==]

local machine_front = require("machine_front")

local function bad(self, vars)
   if type(vars.place) ~= "string" or navigator:place(vars.place .. "_left") == nil then
      self.fsm.error = string.format("get_consumed: unknown machine '%s'", tostring(vars.place))
      return true
   end
   return false
end

local function find(self, vars)
   local x, y, th = pose:get()
   local c, s = math.cos(th), math.sin(th)
   local sides = {"left", "right"}
   if vars.side == "right" then sides = {"right"} elseif vars.side == "left" then sides = {"left"} end
   for _, side in ipairs(sides) do
      local tx, ty = select(4, navigator:place(vars.place .. "_" .. side))
      for i = 1, pucks:count() do
         local rx, ry = pucks:puck(i)
         local fx, fy = x + c * rx - s * ry, y + s * rx + c * ry
         if (fx - tx) ^ 2 + (fy - ty) ^ 2 < 0.12 ^ 2 then
            vars.px, vars.py, vars.found = fx, fy, side
            return true
         end
      end
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"GOTO", SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="FAILED"},
   {"LOOK", JumpState},
   -- carologistics-2013: ADJUST_POS and DRIVE_TO_SIDE before the take.
   {"FRONT", SkillJumpState, skills={{drive_to}}, final_to="SIDE", fail_to="FAILED"},
   {"SIDE", SkillJumpState, skills={{motor_move}}, final_to="TAKE", fail_to="FAILED"},
   {"TAKE", SkillJumpState, skills={{take_puck}}, final_to="TAKEN", fail_to="FAILED"},
   {"TAKEN", JumpState},
   -- carologistics-2013: get_consumed's LEAVE_TURN and LEAVE_FORWARD.
   {"LEAVE_TURN", SkillJumpState, skills={{motor_move}}, final_to="LEAVE_FORWARD",
    fail_to="FAILED"},
   {"LEAVE_FORWARD", SkillJumpState, skills={{motor_move}}, final_to="FINAL", fail_to="FAILED"},
}

fsm:add_transitions{
   {"GOTO", "FAILED", precond="sensor:puck_in_holder()",
    error="get_consumed: already holding a puck"},
   {"GOTO", "FAILED", precond=bad, desc="bad arguments"},
   {"LOOK", "FRONT", cond=function(self, vars)
      return profile.motions == "carologistics-2013" and find(self, vars)
   end, desc="puck found: to the front as the team did"},
   {"LOOK", "TAKE", cond=find, desc="puck found"},
   {"LOOK", "FAILED", timeout={0.6, error="get_consumed: no puck beside the machine"}},
   {"TAKEN", "LEAVE_TURN", cond="profile.motions == 'carologistics-2013'",
    desc="leave as the team did"},
   {"TAKEN", "FINAL", cond=true, desc="taken"},
}

function GOTO:init()
   -- From the look position the puck detection sees both sides of the machine.
   self.fsm.vars.ori = select(3, navigator:place(self.fsm.vars.place .. "_input"))
   self.args["drive_to"] = {place = self.fsm.vars.place .. "_look"}
end

function FRONT:init()
   self.args["drive_to"] = machine_front.before_input(navigator, self.fsm.vars.place, 0.3)
end

function SIDE:init()
   local v = self.fsm.vars
   -- The puck's side in the robot's frame: -1 right (the team's), 1 left (mirrored).
   local x, y, th = pose:get()
   local ey = -math.sin(th) * (v.px - x) + math.cos(th) * (v.py - y)
   v.sign = ey < 0 and -1 or 1
   self.args["motor_move"] = {x = 0.1, y = 0.4 * v.sign, ori = -0.3 * v.sign}
end

function LEAVE_TURN:init()
   -- The team turned by -3.0 rad after going right: away from the machine.
   self.args["motor_move"] = {ori = 3.0 * (self.fsm.vars.sign or -1)}
end

function LEAVE_FORWARD:init()
   self.args["motor_move"] = {x = 0.5}
end

function TAKE:init()
   local v = self.fsm.vars
   self.fsm.result = v.found
   self.args["take_puck"] = {x = v.px, y = v.py, ori = v.ori}
end
