-- SPDX-License-Identifier: MIT
-- drive_to: the navigator to a named place or a pose.
name               = "drive_to"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = nil
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
}
documentation      = [==[Drives to a named place or to a pose with the navigator.
@param place         a place name: "M3" (= "M3_input"), "M3_left", "M3_look", "INS_2",
                     "LATE_ORDER", "WAIT_INS", ... (see docs/planner.md "Places")
@param x, y          a field pose instead of a place (metres)
@param ori           heading at the pose (rad, default 0)
@param forward_only  keep the holder in front, never drive backwards (default: true while a
                     puck is in the holder, so that it is not lost)
@param timeout       seconds before giving up (default 120; none without stuck detection,
                     profile.stuck_detection false)
Fails: "drive_to needs place=<name> or x=, y=", the navigator's outcome with its reason
("navigator NO_PATH: ...", "INVALID_GOAL: unknown place 'M11'", "BLOCKED by robot2",
"STUCK: ..."), or "no arrival within N s".
]==]

local function navigator_failed(self)
   if navigator:failed() and navigator:msgid() == self.fsm.vars.msgid then
      local status = navigator:status()
      local why = navigator:error_message()
      if status == "BLOCKED" and navigator:blocked_by() ~= "" then
         why = "by " .. navigator:blocked_by() .. (why ~= "" and (": " .. why) or "")
      end
      self.fsm.error = string.format("navigator %s: %s", status, why)
      if status == "ABORTED" then self.fsm.reason = "aborted" end
      return true
   end
   return false
end

local function timed_out(self, vars)
   -- Without stuck detection (profile.stuck_detection false) there is no timeout.
   if not profile.stuck_detection or clock.now() < vars.deadline then return false end
   self.fsm.error = string.format("no arrival within %g s", vars.timeout or 120)
   return true
end

-- What was given, for the error: `"1.5" (a string)`, `nil`.
local function given(v)
   if type(v) == "string" then return string.format("%q (a string)", v) end
   return tostring(v)
end

local function bad_args(self, vars)
   local why
   if vars.place ~= nil then
      if type(vars.place) ~= "string" then
         why = "place= must be a place name, not " .. given(vars.place)
      end
   elseif type(vars.x) ~= "number" or type(vars.y) ~= "number" then
      why = string.format("x= and y= must be numbers (got x=%s, y=%s)", given(vars.x),
                          given(vars.y))
   end
   if why then self.fsm.error = "drive_to needs place=<name> or x=, y=: " .. why end
   return why ~= nil
end

fsm:define_states{ export_to=_M,
   {"DRIVE", JumpState},
}

fsm:add_transitions{
   {"DRIVE", "FAILED", precond=bad_args},
   {"DRIVE", "FINAL", cond="navigator:arrived() and navigator:msgid() == vars.msgid",
    desc="arrived"},
   {"DRIVE", "FAILED", cond=navigator_failed, desc="navigator failed"},
   {"DRIVE", "FAILED", cond=timed_out, desc="timeout"},
}

function DRIVE:init()
   local v = self.fsm.vars
   local forward = v.forward_only
   if forward == nil then forward = sensor:puck_in_holder() end
   v.deadline = clock.now() + (v.timeout or 120)
   if v.place ~= nil then
      navigator:goto_place(v.place, forward)
   else
      navigator:goto_pose(v.x, v.y, v.ori or 0, forward)
   end
   v.msgid = navigator:msgid()
end

function DRIVE:exit()
   -- Aborted (new skill string, stop, timeout): do not leave the robot driving.
   if not navigator:arrived() then navigator:stop() end
end
