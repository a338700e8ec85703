-- SPDX-License-Identifier: MIT
-- Reference solution of exercises/01-drive-to-point (tests/app/exercise_test.cpp).
name               = "drive_to_point"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
}
documentation      = [==[Drives the robot to a point of the field.
@param x, y  the point (field coordinates, metres)
]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{
   {"CHECK", "FINAL", cond=function(self, vars) return pose:distance_to(vars.x, vars.y) < 0.1 end},
   {"CHECK", "DRIVE", timeout=0.5},
}

function DRIVE:init()
   local x, y = pose:get()
   self.args["drive_to"] = {x = self.fsm.vars.x, y = self.fsm.vars.y,
                            ori = math.atan(self.fsm.vars.y - y, self.fsm.vars.x - x)}
end
