-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): self.args set in a JumpState, which runs no
-- sub-skill (a warning). Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", JumpState},
}

fsm:add_transitions{
   {"DRIVE", "FINAL", timeout=1},
}

function DRIVE:init()
   self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y}  -- MISTAKE
end
