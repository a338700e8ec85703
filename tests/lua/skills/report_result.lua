-- SPDX-License-Identifier: MIT
-- Test skill: reports a result, then ends FINAL or FAILED as asked.
name               = "report_result"
fsm                = SkillHSM:new{name=name, start="WORK"}
depends_skills     = nil
depends_interfaces = nil
documentation      = [==[Sets fsm.result to `text`; fails if `fail` is true.
@param text  the result
@param fail  end FAILED instead of FINAL
]==]

fsm:define_states{ export_to=_M,
   {"WORK", JumpState},
}

fsm:add_transitions{
   {"WORK", "FAILED", cond="vars.fail", error="asked to fail"},
   {"WORK", "FINAL", cond=true},
}

function WORK:init()
   self.fsm.result = self.fsm.vars.text
end
