-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): no `documentation`. Exercise 01.
name               = "drive_to_point"  -- MISTAKE
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}
