-- SPDX-License-Identifier: MIT
-- Hostile exercise skill: a table that grows every cycle until memory runs out
name = "drive_to_point"
fsm = SkillHSM:new{name=name, start="S"}
documentation = [==[hostile]==]
fsm:define_states{ export_to=_M, {"S", JumpState} }
fsm:add_transitions{ {"S", "FINAL", cond="vars.done"} }
local hoard = {}
function S:loop()
   for i = 1, 20000 do hoard[#hoard + 1] = {i, i} end
end
