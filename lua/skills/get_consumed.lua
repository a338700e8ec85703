-- SPDX-License-Identifier: MIT
-- get_consumed: pick up a consumed puck lying beside a machine.
name               = "get_consumed"
fsm                = SkillHSM:new{name=name, start="GOTO"}
depends_skills     = {"drive_to", "take_puck"}
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
]==]

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
   {"TAKE", SkillJumpState, skills={{take_puck}}, final_to="FINAL", fail_to="FAILED"},
}

fsm:add_transitions{
   {"GOTO", "FAILED", precond="sensor:puck_in_holder()",
    error="get_consumed: already holding a puck"},
   {"GOTO", "FAILED", precond=bad, desc="bad arguments"},
   {"LOOK", "TAKE", cond=find, desc="puck found"},
   {"LOOK", "FAILED", timeout={0.6, error="get_consumed: no puck beside the machine"}},
}

function GOTO:init()
   -- From the look position the puck detection sees both sides of the machine.
   self.fsm.vars.ori = select(3, navigator:place(self.fsm.vars.place .. "_input"))
   self.args["drive_to"] = {place = self.fsm.vars.place .. "_look"}
end

function TAKE:init()
   local v = self.fsm.vars
   self.fsm.result = v.found
   self.args["take_puck"] = {x = v.px, y = v.py, ori = v.ori}
end
