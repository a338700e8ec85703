-- SPDX-License-Identifier: MIT
-- A Fawkes-style skill (tests/lua/fawkes_test.cpp): drives through ppgoto to the approach node
-- of a navgraph node, then to the node, the sub-skill's arguments set in self.skills[1].
module(..., skillenv.module_init)

name               = "drive_node"
fsm                = SkillHSM:new{name=name, start="APPROACH"}
depends_skills     = {"ppgoto"}
depends_interfaces = {
   {v = "pose", type = "Position3DInterface", id = "Pose"},
}

documentation      = [==[Drives to the approach node of a node, then to the node.
@param place the navgraph node]==]

local places = require("place_table")

skillenv.skill_module(_M)

graph = fawkes.load_yaml_navgraph("navgraph-test.yaml")

fsm:define_states{ export_to=_M,
   -- (timeout= of a state is llsfsim's: a Fawkes-style file ignores it, as Fawkes did)
   {"APPROACH", SkillJumpState, skills={{ppgoto}}, final_to="NODE", fail_to="FAILED", timeout=0.1},
   {"NODE", SkillJumpState, skills={{ppgoto}}, final_to="FINAL", fail_to="FAILED"},
}

function APPROACH:init()
   self.skills[1].place = places.approach[self.fsm.vars.place] or
                          graph:closest_node_to(self.fsm.vars.place, "orientation"):name()
   self.fsm.vars.approached = self.skills[1].place
end

function NODE:init()
   local node = graph:node(self.fsm.vars.place)
   self.skills[1].place = nil
   self.skills[1].x = node:x()
   self.skills[1].y = node:y()
   self.skills[1].ori = node:property_as_float("orientation")
end

function FINAL:init()
   self.fsm.result = string.format("%s %.2f %.2f %d %s", self.fsm.vars.approached,
                                   pose:translation(0), pose:translation(1),
                                   pose:visibility_history() > 0 and 1 or 0, pose:frame())
end
