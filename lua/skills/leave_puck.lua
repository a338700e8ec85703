-- SPDX-License-Identifier: MIT
-- leave_puck: put the held puck down where it is and back away from it.
name               = "leave_puck"
fsm                = SkillHSM:new{name=name, start="BACK"}
depends_skills     = {"motor_move"}
depends_interfaces = {
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
}
documentation      = [==[Leaves the held puck where it lies: backs straight away from it (the passive
holder lets a puck go when the robot drives backwards).
@param distance  how far to back off (m, default 0.25)
Fails: motor_move's failure (something behind the robot), "leave_puck: the puck is still in the
holder". With an empty holder it just backs off.
]==]

fsm:define_states{ export_to=_M,
   {"BACK",  SkillJumpState, skills={{motor_move}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{
   {"CHECK", "FINAL", cond="not sensor:puck_in_holder()", desc="puck left"},
   {"CHECK", "FAILED", timeout={0.3, error="leave_puck: the puck is still in the holder"}},
}

function BACK:init()
   local d = self.fsm.vars.distance or 0.25
   self.args["motor_move"] = {x = -d, vel_trans = 0.25}
end
