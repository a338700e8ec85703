-- SPDX-License-Identifier: MIT
-- Drives to a place and waits there: sub-skills through SkillJumpState.
name               = "visit_place"
fsm                = SkillHSM:new{name=name, start="GOTO"}
depends_skills     = {"goto_place", "wait_for"}
depends_interfaces = nil
documentation      = [==[Drives to a place, then waits there.
@param place  name of the place (string)
@param secs   seconds to wait on arrival (default 1)
]==]

fsm:define_states{ export_to=_M,
   {"GOTO", SkillJumpState, skills={{goto_place}}, final_to="WAIT", fail_to="FAILED"},
   {"WAIT", SkillJumpState, skills={{wait_for}}, final_to="FINAL"},
}

function GOTO:init()
   self.args["goto_place"] = {place = self.fsm.vars.place}
end

function WAIT:init()
   self.args["wait_for"] = {secs = self.fsm.vars.secs or 1}
end
