-- SPDX-License-Identifier: MIT
-- A Fawkes-style skill (tests/lua/fawkes_test.cpp): drives with MotorInterface messages towards
-- a point given in the map frame, converted with a helper module (require), until the IR
-- sensor sees something close.
module(..., skillenv.module_init)

name               = "nudge"
fsm                = SkillHSM:new{name=name, start="DRIVE"}
depends_skills     = nil
depends_interfaces = {
   {v = "motor", type = "MotorInterface", id = "Robotino"},
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
}

documentation      = [==[Drives towards (x, y) in /map until the puck sensor sees something.
@param x, y the point in the map frame]==]

local frames = require("util.frames")
local NEAR = config:get_float("/skills/nudge/near_dist")

skillenv.skill_module(_M)

function close() return sensor:distance(8) > 0 and sensor:distance(8) < NEAR end

local function send(vx, vy, omega)
   local oc, ocn = motor:controller(), motor:controller_thread_name()
   motor:msgq_enqueue_copy(motor.AcquireControlMessage:new())
   motor:msgq_enqueue_copy(motor.TransRotMessage:new(vx, vy, omega))
   motor:msgq_enqueue_copy(motor.AcquireControlMessage:new(oc, ocn))
end

fsm:define_states{ export_to=_M, closure={motor=motor},
   {"DRIVE", JumpState},
}

fsm:add_transitions{
   {"DRIVE", "FAILED", precond="not motor:has_writer()", desc="no motor"},
   {"DRIVE", "FINAL", cond=close, desc="something close"},
}

function DRIVE:init()
   local rel = frames.transform({x = self.fsm.vars.x, y = self.fsm.vars.y, ori = 0},
                                "/map", "/base_link")
   local d = math.sqrt(rel.x ^ 2 + rel.y ^ 2)
   send(0.2 * rel.x / d, 0.2 * rel.y / d, 0)
end

function DRIVE:exit()
   send(0, 0, 0)
end
