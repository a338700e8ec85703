-- SPDX-License-Identifier: MIT
-- Waits a number of seconds of simulated time.
name               = "wait_for"
fsm                = SkillHSM:new{name=name, start="WAIT"}
depends_skills     = nil
depends_interfaces = nil
documentation      = [==[Waits, then ends FINAL.
@param secs  seconds of simulated time to wait (number >= 0)
]==]

fsm:define_states{ export_to=_M,
   {"WAIT", JumpState},
}

fsm:add_transitions{
   -- Checked on entry, before WAIT:init(): bad arguments fail at once.
   {"WAIT", "FAILED", precond="type(vars.secs) ~= 'number' or vars.secs < 0",
    error="wait_for needs secs=<number >= 0>"},
   {"WAIT", "FINAL", cond="clock.now() >= vars.deadline", desc="time is up"},
}

function WAIT:init()
   self.fsm.vars.deadline = clock.now() + self.fsm.vars.secs
end
