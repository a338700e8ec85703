-- SPDX-License-Identifier: MIT
-- A Fawkes-style skill (tests/lua/fawkes_test.cpp): waits for a ready light reading, switches
-- the vision on and off with SwitchInterface messages and writes what it saw to the
-- RobotinoLightInterface "Light determined".
module(..., skillenv.module_init)

name               = "read_light"
fsm                = SkillHSM:new{name=name, start="WAIT"}
depends_skills     = nil
depends_interfaces = {
   {v = "plugin", type = "RobotinoLightInterface", id = "Light_State"},
   {v = "output", type = "RobotinoLightInterface", id = "Light determined", writing = true},
   {v = "lightswitch", type = "SwitchInterface", id = "light_front_switch"},
   {v = "ampel_green", type = "SwitchInterface", id = "ampel_green"},
   {v = "sensor", type = "RobotinoSensorInterface"},
}

documentation      = [==[Reads the signal in front and writes it to "Light determined".]==]

skillenv.skill_module(_M)

fsm:define_states{ export_to=_M, closure={plugin=plugin},
   {"WAIT", JumpState},
}

fsm:add_transitions{
   {"WAIT", "FINAL", cond="plugin:is_ready() and plugin:visibility_history() >= 3"},
   {"WAIT", "FAILED", timeout=2, desc="no signal"},
}

function WAIT:init()
   lightswitch:msgq_enqueue_copy(lightswitch.EnableSwitchMessage:new())
end

function FINAL:init()
   lightswitch:msgq_enqueue_copy(lightswitch.DisableSwitchMessage:new())
   output:set_red(plugin:red())
   output:set_yellow(plugin:yellow())
   output:set_green(plugin:green())
   output:set_ready(true)
   output:write()
   self.fsm.result = string.format("%s %s %s green=%s switch=%s optical=%g,%g",
                                   output:red(), output:yellow(), output:green(),
                                   tostring(ampel_green:is_enabled()),
                                   tostring(lightswitch:is_enabled()),
                                   sensor:analog_in(0), sensor:analog_in(4))
end
