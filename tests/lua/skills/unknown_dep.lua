-- SPDX-License-Identifier: MIT
-- Test skill: depends on a skill that does not exist.
name               = "unknown_dep"
fsm                = SkillHSM:new{name=name, start="A"}
depends_skills     = {"say_hello", "no_such_skill"}  -- MARK
documentation      = "unknown dependency"
fsm:define_states{ export_to=_M, {"A", JumpState} }
