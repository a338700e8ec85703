-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): coordinates passed to drive_to as strings.
-- Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}

function DRIVE:init()
   self.args["drive_to"] = {x = "1.5", y = "2"}  -- MISTAKE
end
