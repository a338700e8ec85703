-- SPDX-License-Identifier: MIT
-- park: drive to a parking spot out of the way.
name               = "park"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = {"drive_to"}
depends_interfaces = nil
documentation      = [==[Drives to a parking spot: by default this robot's spot at the insertion
area (robotN: x 0.5, y 0.4 + 0.6 (N - 1), facing the field: in front of the 2013 start poses,
which lie closer to the wall than the navigator lets a robot stand), or any place given.
@param place  a place name instead (e.g. "WAIT_INS", "WAIT_DELIVERY")
Fails: drive_to's failure.
]==]

fsm:define_states{ export_to=_M,
   {"DRIVE", SkillJumpState, skills={{drive_to}}, final_to="FINAL", fail_to="FAILED"},
}

function DRIVE:init()
   local v = self.fsm.vars
   if v.place ~= nil then
      self.args["drive_to"] = {place = v.place}
   else
      local n = tonumber(string.match(robot_name, "(%d+)$")) or 1
      self.args["drive_to"] = {x = 0.5, y = 0.4 + 0.6 * ((n - 1) % 3), ori = 0}
   end
end
