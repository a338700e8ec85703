-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): no fsm:define_states{...}. Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}  -- MISTAKE
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]
