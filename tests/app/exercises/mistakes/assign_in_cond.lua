-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): `=` instead of `==` in a string condition. Exercise
-- 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="WAIT"}
depends_skills     = {}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"WAIT", JumpState},
}

fsm:add_transitions{ {"WAIT", "FINAL", cond="vars.x = 1"} }  -- MISTAKE
