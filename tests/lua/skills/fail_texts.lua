-- SPDX-License-Identifier: MIT
-- Test skill: the failure texts the engine makes up when a transition carries no error=.
name               = "fail_texts"
fsm                = SkillHSM:new{name=name, start="CHECK"}
documentation      = [==[Fails in the way `mode` says.
@param mode  "precond", "cond", "hook" or "wait"
]==]

fsm:define_states{ export_to=_M, {"CHECK", JumpState} }

fsm:add_transitions{
   {"CHECK", "FAILED", precond="vars.mode == 'precond'"},
   {"CHECK", "FAILED", cond="vars.mode == 'cond'"},
   {"CHECK", "FAILED", timeout=0.1},
}

function CHECK:loop()
   if self.fsm.vars.mode == "hook" then self.fsm.error = "set by the loop hook" end
end
