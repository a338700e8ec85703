-- SPDX-License-Identifier: MIT
-- Exercise 4: rescue as many pucks as possible in 5 minutes (README.md). Run it with
--   llsfsim exercise 04 --skill THIS_FILE
-- One call of the skill brings one puck of a counted colour to the safe area.
name               = "rescue"           -- keep: the exercise loads this file as rescue
fsm                = SkillHSM:new{name=name, start="LOOK"}
depends_skills     = {"drive_to", "take_puck", "leave_puck"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
   {v = "motor", type = "MotorInterface"},
   {v = "sensor", type = "RobotinoSensorInterface"},
   {v = "puck_detector", type = "ColourPuckInterface"},
   {v = "rescue", type = "RescueInterface"},
}
documentation      = [==[Brings one puck of a counted colour to the safe area.]==]

-- Robot frame (x ahead, y left) to field frame.
local function to_field(rx, ry)
   local x, y, th = pose:get()
   return x + math.cos(th) * rx - math.sin(th) * ry, y + math.sin(th) * rx + math.cos(th) * ry
end

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
   {"TAKE", SkillJumpState, skills={{take_puck}}, final_to="BRING", fail_to="FAILED"},
   {"BRING", SkillJumpState, skills={{drive_to}}, final_to="LEAVE", fail_to="FAILED"},
   {"LEAVE", SkillJumpState, skills={{leave_puck}}, final_to="FINAL", fail_to="FAILED"},
}

fsm:add_transitions{
   -- TODO 1: {"LOOK", "TAKE", cond=function(self, vars) ... end}: when
   --   puck_detector:nearest(rescue:colours()) returns x, y (robot frame), store
   --   vars.px, vars.py = to_field(x, y) and return true.
   -- TODO 2: search while nothing is in sight: turn on the spot (motor:set_velocity) and drive
   --   to other places of the field (a state with drive_to); see the README's hints.
   -- TODO 3 (exercises 4 and 5): do not fail when take_puck or drive_to fails: go back to
   --   searching (fail_to="LOOK"), and do not take decoys (rescue:is_decoy(colour)).
   {"LOOK", "FAILED", cond=true, error="not solved yet: fill in the TODOs of skill.lua"},
}

function TAKE:init() self.args["take_puck"] = {x = self.fsm.vars.px, y = self.fsm.vars.py} end
function BRING:init() self.args["drive_to"] = {place = rescue:safe_place()} end
function LEAVE:init() self.args["leave_puck"] = {distance = 0.3} end
