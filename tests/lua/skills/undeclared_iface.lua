-- SPDX-License-Identifier: MIT
-- Test skill: uses the navigator without declaring it.
name               = "undeclared_iface"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_interfaces = nil
documentation      = "undeclared interface"
fsm:define_states{ export_to=_M, {"DRIVE", JumpState} }
fsm:add_transitions{ {"DRIVE", "FINAL", cond=true} }
function DRIVE:init()
   navigator:goto_place("M1")  -- MARK
end
