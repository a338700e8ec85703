-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): the reference solution of exercise 02 with
-- another colour's puck reported (the first green sighting); the verdict's `why` names
-- what was reported.
name               = "find_red_puck"
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

-- Along the lanes between the machines, clear of the boxes (a lookout next to one would be
-- no goal for the navigator).
local LOOKOUTS = {
   {1.12, 1.12}, {2.24, 1.12}, {3.36, 1.12}, {4.25, 0.85},
   {4.48, 2.24}, {3.30, 2.10}, {2.24, 2.24}, {1.12, 2.24},
   {1.12, 3.36}, {2.24, 3.36}, {3.36, 3.36}, {4.48, 3.36},
   {4.48, 4.48}, {3.20, 4.40}, {2.24, 4.48}, {0.85, 4.65},
}

local function to_field(rx, ry)
   local x, y, th = pose:get()
   return x + math.cos(th) * rx - math.sin(th) * ry, y + math.sin(th) * rx + math.cos(th) * ry
end

-- MISTAKE below: a green puck's position is reported.
local function confirmed(self, vars)
   for _, s in ipairs(puck_detector:list()) do
      if s.colour == "green" then
         self.fsm.result = string.format("%.2f %.2f", to_field(s.x, s.y))
         return true
      end
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"LOOK", JumpState},
   {"NEXT", JumpState},
   {"GO", SkillJumpState, skills={{drive_to}}, final_to="LOOK", fail_to="NEXT"},
}

fsm:add_transitions{
   {"LOOK", "FINAL", cond=confirmed},
   {"LOOK", "NEXT", timeout=6.5},
   {"GO", "FINAL", cond=confirmed},
   {"NEXT", "FAILED", cond=function(self, vars) return vars.i > #LOOKOUTS end,
    error="no red puck found"},
   {"NEXT", "GO", cond=true},
}

function LOOK:init() motor:set_velocity(0, 0, 1.0) end
function LOOK:exit() motor:stop() end

function NEXT:init() self.fsm.vars.i = (self.fsm.vars.i or 0) + 1 end

function GO:init()
   local p = LOOKOUTS[self.fsm.vars.i]
   self.args["drive_to"] = {x = p[1], y = p[2]}
end
