-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): no `fsm = SkillHSM:new{...}`. Exercise 01.
name               = "drive_to_point"
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,  -- MISTAKE
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}
