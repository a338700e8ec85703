-- SPDX-License-Identifier: MIT
-- explore_machine: read a machine's signal light code (exploration phase).
name               = "explore_machine"
fsm                = SkillHSM:new{name=name, start="GOTO"}
depends_skills     = {"drive_to"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "light",     type = "RobotinoLightInterface", id = "Light"},
}
documentation      = [==[Drives to a device's look position and reads a stable light code. The
result is "<device> red=<L> yellow=<L> green=<L>" with L one of ON, OFF, BLINK (the 2013
refbox's LightState names, as in its ExplorationInfo signals), e.g.
"M3 red=ON yellow=OFF green=BLINK" (the exploration phase's type code).
@param place   the device: "M1".."M10" (also "R1", "R2", "TST", "D1".."D3")
@param stable  seconds the reading must hold unchanged (default 1.2: a blink period and more)
@param timeout seconds to wait for a stable reading at the look position (default 8)
Fails: "explore_machine: unknown device 'X'", drive_to's failure, "explore_machine: no stable
light of M3 within 8 s (sees M4)".
]==]

local function bad(self, vars)
   if type(vars.place) ~= "string" or navigator:place(vars.place .. "_look") == nil then
      self.fsm.error = string.format("explore_machine: unknown device '%s'", tostring(vars.place))
      return true
   end
   return false
end

local function stable(self, vars)
   return light:visible() and light:device() == vars.place and
          light:stable_for() >= (vars.stable or 1.2)
end

local function give_up(self, vars)
   if clock.now() - vars.since < (vars.timeout or 8) then return false end
   local sees = light:visible() and light:device() or "nothing"
   self.fsm.error = string.format("explore_machine: no stable light of %s within %g s (sees %s)",
                                  vars.place, vars.timeout or 8, sees)
   return true
end

fsm:define_states{ export_to=_M,
   {"GOTO", SkillJumpState, skills={{drive_to}}, final_to="READ", fail_to="FAILED"},
   {"READ", JumpState},
}

fsm:add_transitions{
   {"GOTO", "FAILED", precond=bad, desc="bad arguments"},
   {"READ", "FINAL", cond=stable, desc="stable reading"},
   {"READ", "FAILED", cond=give_up, desc="no reading"},
}

function GOTO:init()
   self.args["drive_to"] = {place = self.fsm.vars.place .. "_look"}
end

function READ:init()
   self.fsm.vars.since = clock.now()
end

-- A lamp's state by the refbox's LightState name (the light interface says BLINKING, as in
-- Fawkes' RobotinoLightInterface; the refbox says BLINK).
local function refbox_name(v)
   if v == light.BLINKING then return "BLINK" end
   return v
end

function READ:exit()
   if stable(self, self.fsm.vars) then
      self.fsm.result = string.format("%s red=%s yellow=%s green=%s", self.fsm.vars.place,
                                      refbox_name(light:red()), refbox_name(light:yellow()),
                                      refbox_name(light:green()))
   end
end
