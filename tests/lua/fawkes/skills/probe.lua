-- SPDX-License-Identifier: MIT
-- A Fawkes-style skill (tests/lua/fawkes_test.cpp): the relative navigator (NavigatorInterface
-- "Navigator"), the puck detection as Position3DInterface "OmniPuck<n>", fawkes.Time.
module(..., skillenv.module_init)

name               = "probe"
fsm                = SkillHSM:new{name=name, start="GO"}
depends_skills     = nil
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "omnipuck1", type = "Position3DInterface", id = "OmniPuck1"},
   {v = "omnipuck2", type = "Position3DInterface", id = "OmniPuck2"},
   {v = "closest", type = "Position3DInterface", id = "Closest_Machine"},
   {v = "skiller", type = "SkillerInterface"},
}

documentation      = [==[Sends a relative goal and reports what the interfaces say.]==]

skillenv.skill_module(_M)

function arrived(state)
   return navigator:msgid() == state.fsm.vars.msgid and navigator:is_final()
end

fsm:define_states{ export_to=_M,
   {"GO", JumpState},
}

fsm:add_transitions{
   {"GO", "FINAL", cond=arrived},
}

function GO:init()
   self.fsm.vars.start = fawkes.Time:new()
   self.fsm.vars.msgid = navigator:msgq_enqueue_copy(navigator.CartesianGotoMessage:new(1.0, 0.0, 0.0))
end

function FINAL:init()
   local v = self.fsm.vars
   v.elapsed = fawkes.Time:new() - v.start
   self.fsm.result = string.format("dest=%.2f,%.2f puck1=%.2f,%.2f vis1=%s vis2=%s closest=%s " ..
                                   "elapsed=%s skiller=%s/%d",
      navigator:dest_x(), navigator:dest_y(), omnipuck1:translation(0), omnipuck1:translation(1),
      tostring(omnipuck1:visibility_history() > 1), tostring(omnipuck2:visibility_history() < 0),
      tostring(closest:has_writer()), tostring(v.elapsed > 0), skiller:skill_string(),
      skiller:status())
end
