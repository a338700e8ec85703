-- SPDX-License-Identifier: MIT
-- motor_move at the symbolic level: wait the time the move takes, then be there.
name               = "motor_move"
fsm                = SkillHSM:new{name=name, start="MOVE"}
depends_skills     = nil
depends_interfaces = {
   {v = "pose",   type = "Position3DInterface", id = "Pose"},
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "sym",    type = "SymbolicInterface", id = "Symbolic"},
}
documentation      = [==[Symbolic motor_move: same arguments as the physical skill (x, y, ori,
vel_trans, vel_rot, tolerance). Waits distance over vel_trans plus the turn over vel_rot, then
puts the robot at the goal; moving backwards (x < 0) faster than 0.02 m/s leaves a held puck
where it was (as the assisted holder does).
]==]

local OFFSET = 0.2225

local function bad_args(self, vars)
   for _, k in ipairs{"x", "y", "ori", "vel_trans", "vel_rot", "tolerance"} do
      if vars[k] ~= nil and type(vars[k]) ~= "number" then return true end
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"MOVE",   JumpState},
   {"ARRIVE", JumpState},
}

fsm:add_transitions{
   {"MOVE", "FAILED", precond=bad_args, error="motor_move needs numbers x, y, ori"},
   {"MOVE", "ARRIVE", cond="clock.now() >= vars.arrive_at", desc="time is up"},
   {"ARRIVE", "FINAL", timeout=0.05},
}

function MOVE:init()
   local v = self.fsm.vars
   local x, y, th = pose:get()
   local dx, dy, dth = v.x or 0, v.y or 0, v.ori or 0
   local c, s = math.cos(th), math.sin(th)
   v.gx, v.gy, v.gth = x + c * dx - s * dy, y + s * dx + c * dy, th + dth
   v.arrive_at = clock.now() + math.sqrt(dx * dx + dy * dy) / (v.vel_trans or 0.3) +
                 math.abs(dth) / (v.vel_rot or 1.0)
   -- The assisted holder lets go only when backing faster than 0.02 m/s.
   if dx < 0 and (v.vel_trans or 0.3) > 0.02 and sensor:puck_in_holder() then
      v.drop_x, v.drop_y = x + c * OFFSET, y + s * OFFSET   -- the holder lets go when backing
   end
end

function ARRIVE:init()
   local v = self.fsm.vars
   sym:move(v.gx, v.gy, v.gth)
   if v.drop_x then sym:drop(v.drop_x, v.drop_y) end   -- after the move: the puck stays behind
end
