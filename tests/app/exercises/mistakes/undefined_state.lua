-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a transition to a state that is not defined
-- ("CHEK" for "CHECK"). Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{  -- MISTAKE
   {"DRIVE", "CHEK", timeout=20},
}
