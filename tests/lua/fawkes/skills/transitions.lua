-- SPDX-License-Identifier: MIT
-- A Fawkes-style skill (tests/lua/fawkes_test.cpp): Fawkes' add_transitions (the condition as
-- third entry, precond= as condition and precondition both), an unknown global read as nil.
module(..., skillenv.module_init)

name               = "transitions"
fsm                = SkillHSM:new{name=name, start="START"}
depends_skills     = nil
depends_interfaces = nil

documentation      = [==[Goes START -> WAIT -> FINAL; FAILED at once with fail=true.]==]

skillenv.skill_module(_M)

fsm:define_states{ export_to=_M, closure={no_such_function=no_such_function},
   {"START", JumpState},
   {"WAIT", JumpState},
}

fsm:add_transitions{
   {"START", "FAILED", precond="vars.fail"},
   {"START", "WAIT", true},
   {"WAIT", "FINAL", "vars.count >= 3"},
}

function WAIT:init() self.fsm.vars.count = 0 end
function WAIT:loop() self.fsm.vars.count = self.fsm.vars.count + 1 end

function FINAL:init()
   self.fsm.result = string.format("count=%d closure=%s", self.fsm.vars.count,
                                   tostring(self.fsm.closure.no_such_function))
end
