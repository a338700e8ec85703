-- SPDX-License-Identifier: MIT
-- Test skill: declares an interface type that does not exist.
name               = "bad_iface"
fsm                = SkillHSM:new{name=name, start="A"}
depends_interfaces = { {v="foo", type="FooInterface"} }  -- MARK
documentation      = "unknown interface type"
fsm:define_states{ export_to=_M, {"A", JumpState} }
