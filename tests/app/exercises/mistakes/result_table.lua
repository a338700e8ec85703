-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): fsm.result set to a table (a string "X Y" is
-- expected). Exercise 02.
name               = "find_red_puck"
fsm                = SkillHSM:new{name=name, start="LOOK"}
documentation      = [==[Reports where it believes the red puck is.]==]

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
}

fsm:add_transitions{
   {"LOOK", "FINAL", cond=true},
}

function LOOK:init()
   self.fsm.result = {2.24, 3.36}  -- MISTAKE
end
