-- SPDX-License-Identifier: MIT
-- Drives to a named place with the navigator.
name               = "goto_place"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = nil
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
}
documentation      = [==[Drives to a named place ("M1", "M3_input", "INS_1", ...).
@param place         name of the place (string)
@param forward_only  keep the holder in front (for carrying a puck; default false)
Fails with the navigator's error if there is no path, the place is unknown, the robot is
blocked or stuck, or after 120 s.
]==]

-- A function condition that also says why it holds.
local function navigator_failed(self)
   if navigator:failed() then
      self.fsm.error = string.format("navigator %s: %s", navigator:status(),
                                     navigator:error_message())
      if navigator:status() == "ABORTED" then self.fsm.reason = "aborted" end
      return true
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"DRIVE", JumpState},
}

fsm:add_transitions{
   {"DRIVE", "FAILED", precond="type(vars.place) ~= 'string'", error="goto_place needs place=<name>"},
   {"DRIVE", "FINAL", cond="navigator:arrived() and navigator:msgid() == vars.msgid",
    desc="arrived"},
   {"DRIVE", "FAILED", cond=navigator_failed, desc="navigator failed"},
   {"DRIVE", "FAILED", timeout=120, error="goto_place: no arrival within 120 s"},
}

function DRIVE:init()
   navigator:goto_place(self.fsm.vars.place, self.fsm.vars.forward_only)
   self.fsm.vars.msgid = navigator:msgid()
end

function DRIVE:exit()
   -- Aborted (new skill string, stop, timeout): do not leave the robot driving.
   if not navigator:arrived() then navigator:stop() end
end
