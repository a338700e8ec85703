-- SPDX-License-Identifier: MIT
-- Exercise 2: find the red puck (README.md). Run it with
--   llsfsim exercise 02 --skill THIS_FILE
name               = "find_red_puck"    -- keep: the exercise loads this file as find_red_puck
fsm                = SkillHSM:new{name=name, start="LOOK"}
depends_skills     = {"drive_to"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface"},
   {v = "motor", type = "MotorInterface"},
   {v = "puck_detector", type = "ColourPuckInterface"},
}
documentation      = [==[Searches the field for a red puck and reports its field position in
fsm.result ("X Y").
]==]

-- Points to look from (TODO 3: more of them, so that the whole field is seen).
local LOOKOUTS = { {2.24, 2.24} }

-- Robot frame (x ahead, y left) to field frame.
local function to_field(rx, ry)
   local x, y, th = pose:get()
   return x + math.cos(th) * rx - math.sin(th) * ry, y + math.sin(th) * rx + math.cos(th) * ry
end

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
   {"GO", SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="FAILED"},
}

fsm:add_transitions{
   -- TODO 1: a transition {"LOOK", "FINAL", cond=function(self, vars) ... end}: when
   --   puck_detector:nearest("red") returns x, y (robot frame), turn them into field
   --   coordinates with to_field(x, y), report them with
   --   self.fsm.result = string.format("%.2f %.2f", fx, fy) and return true.
   -- TODO 2: turn on the spot while looking (motor:set_velocity(0, 0, 1) in LOOK:init(),
   --   motor:stop() in LOOK:exit()); after a full turn (timeout) drive to the next lookout.
   {"LOOK", "FAILED", cond=true, error="not solved yet: fill in the TODOs of skill.lua"},
}

function GO:init()
   local p = LOOKOUTS[1]   -- TODO 3: the next lookout each time (keep an index in self.fsm.vars)
   self.args["drive_to"] = {x = p[1], y = p[2]}
end
