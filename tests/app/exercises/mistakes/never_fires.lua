-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a transition after one with cond=true from the
-- same state can never fire (the first is always taken), found at load. Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{  -- MISTAKE
   {"CHECK", "DRIVE", cond=true},
   {"CHECK", "FINAL", cond="vars.done"},
}
