-- SPDX-License-Identifier: MIT
-- Test skill: every transition kind (true, function, string, timeout, precond, default).
name               = "dsl_probe"
fsm                = SkillHSM:new{name=name, start="START"}
depends_skills     = nil
depends_interfaces = {
   {v = "sensor", type = "RobotinoSensorInterface"},
}
documentation      = [==[Walks START -> BY_FUNCTION -> BY_STRING -> BY_TIMEOUT -> FINAL.
@param skip  jump from START to SKIPPED by precondition
]==]

skillenv.skill_module(_M)  -- a Fawkes habit, accepted

fsm:define_states{ export_to=_M, closure={limit=3},
   {"START", JumpState},
   {"BY_FUNCTION", JumpState},
   {"BY_STRING", JumpState},
   {"BY_TIMEOUT", JumpState},
   {"SKIPPED", JumpState},
}

fsm:add_transitions{
   {"START", "SKIPPED", precond="vars.skip"},
   {"START", "BY_FUNCTION", cond=true},
   {"BY_FUNCTION", "BY_STRING", cond=function(self) return sensor:puck_in_holder() end},
   {"BY_STRING", "BY_TIMEOUT", cond="vars.loops >= limit"},
   {"BY_TIMEOUT", "FINAL", timeout=0.5},
   {"SKIPPED", "FINAL", cond=true},
   {"FAILED", cond="sensor:optical_left()", error="left optical sensor tripped"},
}

function START:init() print("START init"); self.fsm.vars.loops = 0 end
function BY_STRING:loop() self.fsm.vars.loops = self.fsm.vars.loops + 1 end
function BY_STRING:exit() printf("BY_STRING exit after %d loops", self.fsm.vars.loops) end
function SKIPPED:init() print("SKIPPED init") end
function BY_TIMEOUT:init() printf("BY_TIMEOUT entered at %.3f", clock.now()) end
