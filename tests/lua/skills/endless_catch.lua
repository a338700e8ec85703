-- SPDX-License-Identifier: MIT
-- Test skill: tries to survive the instruction budget by catching its error.
name               = "endless_catch"
fsm                = SkillHSM:new{name=name, start="SPIN"}
documentation      = "never returns, catches errors"
fsm:define_states{ export_to=_M, {"SPIN", JumpState} }
fsm:add_transitions{ {"SPIN", "FINAL", cond="false"} }
function SPIN:loop()
   while true do
      pcall(function() while true do end end)  -- MARK
   end
end
