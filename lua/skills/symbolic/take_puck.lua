-- SPDX-License-Identifier: MIT
-- take_puck at the symbolic level: wait for the approach, then hold the puck.
name               = "take_puck"
fsm                = SkillHSM:new{name=name, start="PLAN"}
depends_skills     = nil
depends_interfaces = {
   {v = "pose",   type = "Position3DInterface", id = "Pose"},
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "sym",    type = "SymbolicInterface", id = "Symbolic"},
}
documentation      = [==[Symbolic take_puck: same arguments and failures as the physical skill
(x, y, ori). Waits the drive to the puck plus HANDLING_S, puts the robot in front of it and the
puck (the one nearest to x, y within 0.15 m) into the holder.
]==]

local OFFSET = 0.2225
local HANDLING_S = 3.0   -- creeping onto the puck

local function bad_args(self, vars)
   return type(vars.x) ~= "number" or type(vars.y) ~= "number"
end

local function plan(self, vars)
   if vars.ori == nil then
      local x, y = pose:get()
      vars.ori = math.atan(vars.y - y, vars.x - x)
   end
   vars.sx = vars.x - math.cos(vars.ori) * OFFSET
   vars.sy = vars.y - math.sin(vars.ori) * OFFSET
   local secs, err = sym:travel(vars.sx - math.cos(vars.ori) * 0.15,
                                vars.sy - math.sin(vars.ori) * 0.15, vars.ori)
   if secs == nil then
      self.fsm.error = "take_puck: navigator " .. err
      return true
   end
   vars.done_at = clock.now() + secs + HANDLING_S
   return true
end

fsm:define_states{ export_to=_M,
   {"PLAN",  JumpState},
   {"WAIT",  JumpState},
   {"PICK",  JumpState},
}

fsm:add_transitions{
   {"PLAN", "FAILED", precond=bad_args, error="take_puck needs x=, y="},
   {"PLAN", "FAILED", precond="sensor:puck_in_holder()", error="take_puck: already holding a puck"},
   {"PLAN", "WAIT", cond=plan, desc="planned"},
   {"WAIT", "PICK", cond="clock.now() >= vars.done_at", desc="time is up"},
   {"PICK", "FINAL", cond="clock.now() >= vars.check_at and sensor:puck_in_holder()", desc="held"},
   {"PICK", "FAILED", cond="clock.now() >= vars.check_at",
    error="take_puck: the puck is gone (not seen where expected)"},
}

function PICK:init()
   local v = self.fsm.vars
   sym:move(v.sx, v.sy, v.ori)
   sym:pick(v.x, v.y, 0.15)
   v.check_at = clock.now() + 0.1
end
