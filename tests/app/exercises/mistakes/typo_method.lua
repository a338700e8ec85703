-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a misspelt interface method (nearst for nearest),
-- found when the condition runs. Exercise 02.
name               = "find_red_puck"
fsm                = SkillHSM:new{name=name, start="LOOK"}
depends_skills     = {}
depends_interfaces = {
   {v = "puck_detector", type = "ColourPuckInterface"},
}
documentation      = [==[Searches the field for a red puck.]==]

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
}

fsm:add_transitions{
   {"LOOK", "FINAL", cond=function(self, vars)
      local x, y = puck_detector:nearst("red")  -- MISTAKE
      return x ~= nil
   end},
}
