-- SPDX-License-Identifier: MIT
-- Hostile exercise skill: a backtracking pattern
name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[hostile]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond="vars.done"} }
function S:loop()
   string.find(string.rep("a", 30000), "a*a*a*a*a*b")
end
