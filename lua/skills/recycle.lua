-- SPDX-License-Identifier: MIT
-- recycle: bring a consumed puck to a recycling machine; it comes back as an S0.
name               = "recycle"
fsm                = SkillHSM:new{name=name, start="GET"}
depends_skills     = {"get_consumed", "finish_puck_at"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "pose",      type = "Position3DInterface", id = "Pose"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
}
documentation      = [==[Recycles a consumed puck: (optionally picks it up beside a machine first,)
brings it to a recycler and waits until the recycler has turned it into an S0, which is then in
the holder (result "DONE").
@param place  the recycler: "R1" or "R2" (default: the nearer one)
@param from   a machine ("M3") to pick the consumed puck from first (get_consumed); without it
              the robot must already hold the puck
Fails: "recycle: no puck in the holder", get_consumed's failure, finish_puck_at's failure (e.g.
"R1 rejected the puck (yellow blinking: invalid input)" for a puck that was not CONSUMED).
]==]

local function nearest_recycler()
   local x, y = pose:get()
   local best, name = math.huge, "R1"
   for _, r in ipairs{"R1", "R2"} do
      local px, py = navigator:place(r .. "_input")
      local d = (px - x) ^ 2 + (py - y) ^ 2
      if d < best then best, name = d, r end
   end
   return name
end

fsm:define_states{ export_to=_M,
   {"GET", SkillJumpState, skills={{get_consumed}}, final_to="PUT", fail_to="FAILED"},
   {"PUT", SkillJumpState, skills={{finish_puck_at}}, final_to="DONE", fail_to="FAILED"},
   {"DONE", JumpState},
}

fsm:add_transitions{
   {"GET", "PUT", precond="vars.from == nil", desc="already holding it"},
   {"PUT", "FAILED", precond="not sensor:puck_in_holder()", error="recycle: no puck in the holder"},
   {"DONE", "FINAL", cond=true, desc="recycled"},
}

function DONE:init()
   self.fsm.result = "DONE"
end

function GET:init()
   self.args["get_consumed"] = {place = self.fsm.vars.from}
end

function PUT:init()
   local v = self.fsm.vars
   v.place = v.place or nearest_recycler()
   self.args["finish_puck_at"] = {place = v.place}
end
