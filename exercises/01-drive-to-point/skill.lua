-- SPDX-License-Identifier: MIT
-- Exercise 1: drive to a point (README.md). Run it with
--   llsfsim exercise 01 --skill THIS_FILE
name               = "drive_to_point"   -- keep: the exercise loads this file as drive_to_point
fsm                = SkillHSM:new{name=name, start="START"}
depends_skills     = {"drive_to"}       -- skills this one may call
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
}
documentation      = [==[Drives the robot to a point of the field.
@param x, y  the point (field coordinates, metres)
]==]

fsm:define_states{ export_to=_M,
   {"START", JumpState},
   -- TODO 1: add a state that drives, e.g.
   --   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}

fsm:add_transitions{
   -- TODO 2: go from START to your driving state instead of failing, e.g.
   --   {"START", "DRIVE", cond=true},
   {"START", "FAILED", cond=true, error="not solved yet: fill in the TODOs of skill.lua"},
}

-- TODO 3: give drive_to its arguments when the state is entered:
--   function DRIVE:init()
--      self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y}
--   end
