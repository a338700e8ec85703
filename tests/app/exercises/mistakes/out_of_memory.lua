-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a table that grows every cycle until the heap
-- limit (64 MiB). Exercise 01.
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
documentation      = [==[Drives the robot to a point of the field.]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}

local seen = {}

function DRIVE:init()
   self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y}
end

function DRIVE:loop()
   for i = 1, 20000 do seen[#seen + 1] = string.rep("x", 1000) .. i end  -- MISTAKE
end
