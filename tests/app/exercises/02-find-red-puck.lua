-- SPDX-License-Identifier: MIT
-- Reference solution of exercises/02-find-red-puck (tests/app/exercise_test.cpp): turns on the
-- spot at lookouts along the lanes until a red puck was seen three times at the same spot.
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

-- True once a red puck was seen at the same spot for 0.3 s (three camera frames: a sighting
-- holds until the next frame, 0.1 s, so counting skill cycles is not enough) and no other
-- colour was seen there meanwhile (the camera sometimes tells a wrong colour).
local function confirmed(self, vars)
   local best, bx, by, bc = 0.15, nil, nil, nil
   for _, s in ipairs(puck_detector:list()) do
      local fx, fy = to_field(s.x, s.y)
      if vars.cx then
         local d = math.sqrt((fx - vars.cx) ^ 2 + (fy - vars.cy) ^ 2)
         if d < best then best, bx, by, bc = d, fx, fy, s.colour end
      elseif s.colour == "red" then
         vars.cx, vars.cy, vars.since = fx, fy, clock.now()
         return false
      end
   end
   if not vars.cx or not bx then return false end
   if bc ~= "red" then vars.cx = nil return false end
   vars.cx, vars.cy = bx, by
   if clock.now() - vars.since < 0.3 then return false end
   self.fsm.result = string.format("%.2f %.2f", bx, by)
   return true
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
