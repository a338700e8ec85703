-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a state nothing leaves (WAIT has no transition or
-- timeout), found at load as a warning instead of "still running" at the end. Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,  -- MISTAKE
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="WAIT", fail_to="FAILED"},
   {"WAIT", JumpState},
}

function DRIVE:init()
   self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y}
end
