-- SPDX-License-Identifier: MIT
-- ppgoto: Fawkes' generic path-planning goto, written for llsfsim from its documented behaviour
-- (docs/fawkes.md, "Fawkes' generic skills"). Skills written for Fawkes name it in
-- depends_skills; add this directory (lua/skills/fawkes) to skills.skill_dirs.
module(..., skillenv.module_init)

name               = "ppgoto"
fsm                = SkillHSM:new{name=name, start="SEND"}
depends_skills     = nil
depends_interfaces = {
   {v = "ppnavi", type = "NavigatorInterface", id = "Pathplan"},
}

documentation      = [==[Drives to a goal through the path planner (NavigatorInterface "Pathplan").
ppgoto{x=X, y=Y[, ori=ORI]}  a pose in the map frame; without ori the robot faces along the
                             direction from the map origin to (X, Y), as Fawkes' ppgoto did
ppgoto{place=PLACE}          a node of a navgraph loaded with fawkes.load_yaml_navgraph (its pos
                             and orientation property), else an llsfsim place
ppgoto{stop=true}            stops the navigator
FINAL when the navigator reports the goal final (as Fawkes' ppgoto, whether it arrived or gave
up: check the pose afterwards); FAILED without arguments, without a navigator, or when another
goal replaced this one.]==]

skillenv.skill_module(_M)

-- Cycles to wait for the navigator to take the goal before a foreign goal id counts as lost.
local TAKE_CYCLES = 20

local function goal_taken(vars) return vars.msgid ~= nil and vars.msgid == ppnavi:msgid() end

function bad_args(state) return state.fsm.vars.bad_args == true end

function lost(state)
   local v = state.fsm.vars
   return v.msgid == 0 or (not goal_taken(v) and state.cycles > TAKE_CYCLES)
end

function done(state) return goal_taken(state.fsm.vars) and ppnavi:is_final() end

fsm:define_states{ export_to=_M, closure={ppnavi=ppnavi},
   {"SEND", JumpState},
}

fsm:add_transitions{
   {"SEND", "FAILED", precond="not ppnavi:has_writer()", desc="no navigator"},
   {"SEND", "FAILED", cond=bad_args, desc="needs x and y, place or stop"},
   {"SEND", "FAILED", cond=lost, desc="the goal was replaced"},
   {"SEND", "FINAL", cond=done, desc="goal final"},
}

function SEND:init()
   local v = self.fsm.vars
   self.cycles = 0
   local msg
   if v.x ~= nil and v.y ~= nil then
      msg = ppnavi.CartesianGotoMessage:new(v.x, v.y, v.ori or math.atan(v.y, v.x))
   elseif v.place ~= nil then
      msg = ppnavi.PlaceGotoMessage:new(v.place)
   elseif v.stop ~= nil then
      msg = ppnavi.StopMessage:new()
   else
      v.bad_args = true
      return
   end
   v.msgid = ppnavi:msgq_enqueue_copy(msg)
end

function SEND:loop()
   self.cycles = self.cycles + 1
end

-- Aborted while the goal runs: stop the robot (a new skill string, stop()).
function SEND:exit()
   if goal_taken(self.fsm.vars) and not ppnavi:is_final() then
      ppnavi:msgq_enqueue_copy(ppnavi.StopMessage:new())
   end
end
