-- SPDX-License-Identifier: MIT
-- The smallest skill: says hello in the log and finishes.
name               = "say_hello"
fsm                = SkillHSM:new{name=name, start="SAY"}
depends_skills     = nil
depends_interfaces = nil
documentation      = [==[Logs a greeting and ends FINAL.
@param who  whom to greet (string, default "world")
]==]

fsm:define_states{ export_to=_M,
   {"SAY", JumpState},
}

fsm:add_transitions{
   {"SAY", "FINAL", cond=true, desc="said it"},
}

function SAY:init()
   printf("%s says hello to %s", robot_name, self.fsm.vars.who or "world")
end
