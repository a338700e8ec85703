-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): an upper-case constant used before it is defined
-- (not a state). Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

local speed = MAX_SPEED  -- MISTAKE

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}
