-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a condition reads vars.reached, but the skill sets
-- vars.arrived, a name not near it: the condition never holds. No warning (a key may be set
-- later), but the verdict's why says vars.reached is never set and what is. Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="START"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"START", JumpState},
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{  -- MISTAKE
   {"START", "DRIVE", cond=true},
   {"CHECK", "FINAL", cond="vars.reached"},
}

function CHECK:init()
   self.fsm.vars.arrived = true
end
