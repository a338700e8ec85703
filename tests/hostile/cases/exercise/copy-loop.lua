-- SPDX-License-Identifier: MIT
-- Hostile exercise skill: big strings copied in a loop
name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[hostile]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond="vars.done"} }
function S:loop()
   local s = string.rep("x", 16 << 20)
   for i = 1, 1000000 do local t = s .. s end
end
