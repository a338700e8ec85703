-- SPDX-License-Identifier: MIT
-- Test skill: a runtime error in the second cycle of a loop hook.
name               = "runtime_error"
fsm                = SkillHSM:new{name=name, start="WORK"}
documentation      = "indexes nil"
fsm:define_states{ export_to=_M, {"WORK", JumpState} }
fsm:add_transitions{ {"WORK", "FINAL", cond="false"} }
function WORK:loop()
   self.fsm.vars.n = (self.fsm.vars.n or 0) + 1
   if self.fsm.vars.n == 2 then
      local t = nil
      t.field = 1  -- MARK
   end
end
