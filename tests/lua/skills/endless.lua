-- SPDX-License-Identifier: MIT
-- Test skill: an endless loop in a loop hook.
name               = "endless"
fsm                = SkillHSM:new{name=name, start="SPIN"}
documentation      = "never returns"
fsm:define_states{ export_to=_M, {"SPIN", JumpState} }
fsm:add_transitions{ {"SPIN", "FINAL", cond="false"} }
function SPIN:loop()
   local n = 0
   while true do n = n + 1 end  -- MARK
end
