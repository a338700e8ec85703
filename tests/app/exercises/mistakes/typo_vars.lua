-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a condition reads vars.arived, but the skill sets
-- vars.arrived: the condition never holds. A warning after 5 s in the state, and the verdict's
-- why names the state and the condition. Exercise 01.
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
   {"CHECK", "FINAL", cond="vars.arived"},
}

function CHECK:init()
   self.fsm.vars.arrived = true
end
