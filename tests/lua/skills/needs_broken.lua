-- SPDX-License-Identifier: MIT
-- Test skill: depends on a skill that fails to load.
name               = "needs_broken"
fsm                = SkillHSM:new{name=name, start="RUN"}
depends_skills     = {"broken_syntax"}
documentation      = "broken dependency"
fsm:define_states{ export_to=_M,
   {"RUN", SkillJumpState, skills={{broken_syntax}}, final_to="FINAL"},
}
