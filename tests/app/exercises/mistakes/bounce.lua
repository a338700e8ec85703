-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): two states bouncing with cond=true: the skill
-- never waits for anything (a warning). It gives up after 150 cycles (5 s) to end the run early.
-- Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="PLAN"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"PLAN", JumpState},
   {"CHECK", JumpState},
}

fsm:add_transitions{  -- MISTAKE
   {"PLAN", "CHECK", cond=true},
   {"CHECK", "PLAN", cond=true},
}

local cycles = 0
function PLAN:loop()
   cycles = cycles + 1
   if cycles > 150 then self.fsm.error = "gave up" end
end
