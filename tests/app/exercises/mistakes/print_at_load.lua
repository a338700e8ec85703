-- SPDX-License-Identifier: MIT
-- Mistake? (tests/app/exercise_hints_test.cpp): print while the file loads: shown (it used to
-- be dropped). Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="WAIT"}
documentation      = [==[Prints while it loads.]==]
print("loading drive_to_point, version 3")  -- MISTAKE

fsm:define_states{ export_to=_M,
   {"WAIT", JumpState},
}

fsm:add_transitions{
   {"WAIT", "FINAL", timeout=0.5},
}
