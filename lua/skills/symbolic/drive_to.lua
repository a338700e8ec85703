-- SPDX-License-Identifier: MIT
-- drive_to at the symbolic level: wait the estimated driving time, then be there.
name               = "drive_to"
fsm                = SkillHSM:new{name=name, start="PLAN"}
depends_skills     = nil
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "sym",       type = "SymbolicInterface", id = "Symbolic"},
}
documentation      = [==[Symbolic drive_to: same arguments and failures as the physical skill
(place, or x, y, ori; forward_only is accepted and ignored; timeout). Plans the path, waits its
length over the cruise speed plus the turning time (levels.symbolic), then puts the robot (and
the puck it holds) at the goal.
]==]

local function bad_args(self, vars)
   if vars.place ~= nil then return type(vars.place) ~= "string" end
   return type(vars.x) ~= "number" or type(vars.y) ~= "number"
end

local function plan(self, vars)
   if vars.place ~= nil then
      local x, y, th = navigator:place(vars.place)
      if x == nil then
         self.fsm.error = string.format("navigator INVALID_GOAL: unknown place '%s'", vars.place)
         return true
      end
      vars.gx, vars.gy, vars.gth = x, y, th
   else
      vars.gx, vars.gy, vars.gth = vars.x, vars.y, vars.ori or 0
   end
   local secs, err = sym:travel(vars.gx, vars.gy, vars.gth)
   if secs == nil then
      self.fsm.error = "navigator " .. err
      return true
   end
   if secs > (vars.timeout or 120) then
      self.fsm.error = string.format("no arrival within %g s", vars.timeout or 120)
      return true
   end
   vars.arrive_at = clock.now() + secs
   return true
end

fsm:define_states{ export_to=_M,
   {"PLAN",   JumpState},
   {"DRIVE",  JumpState},
   {"ARRIVE", JumpState},
}

fsm:add_transitions{
   {"PLAN", "FAILED", precond=bad_args, error="drive_to needs place=<name> or x=, y="},
   {"PLAN", "DRIVE", cond=plan, desc="planned"},
   {"DRIVE", "ARRIVE", cond="clock.now() >= vars.arrive_at", desc="time is up"},
   {"ARRIVE", "FINAL", timeout=0.05},
}

function ARRIVE:init()
   local v = self.fsm.vars
   sym:move(v.gx, v.gy, v.gth)
end
