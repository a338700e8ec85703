-- SPDX-License-Identifier: MIT
-- Test skill: a syntax error.
name               = "broken_syntax"
fsm                = SkillHSM:new{name=name, start="A"}
documentation      = "broken"
fsm:define_states{ export_to=_M, {"A", JumpState} }
function A:loop()
   if then  -- MARK
end
