-- SPDX-License-Identifier: MIT
-- Hostile exercise skill: a syntax error
name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[hostile]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond="vars.done"} }
function S:loop()
   if self then
end
