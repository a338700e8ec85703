-- SPDX-License-Identifier: MIT
-- leave_puck: put the held puck down (where it is, or out of the way) and back away from it.
name               = "leave_puck"
fsm                = SkillHSM:new{name=name, start="START"}
depends_skills     = {"motor_move", "drive_to"}
depends_interfaces = {
   {v = "sensor", type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "pose",   type = "Position3DInterface", id = "Pose"},
}
documentation      = [==[Leaves the held puck: backs straight away from it (the passive holder lets a
puck go when the robot drives backwards). Without a place it stays where it is.
@param distance  how far to back off (m, default 0.25)
@param place     "AWAY": first carry the puck to the nearest dump spot, against a wall where
                 neither the storage, the delivery zone, a machine's places nor the robots'
                 parking spots are, and leave it there (for a stray or unusable puck, which left
                 in front of the storage or a machine would be swept up again by the next robot
                 driving there); each robot leaves its pucks side by side along the wall, and a
                 spot it cannot reach is passed for the next nearest one
Fails: motor_move's failure (something behind the robot), "leave_puck: the puck is still in the
holder", "leave_puck: unknown place 'X'", with AWAY drive_to's failure at the last spot tried.
With an empty holder it just backs off; with AWAY and an empty holder it does nothing.
]==]

-- Dump spots: a point on a wall (x, y) and the heading that faces it. Chosen off the storage
-- (left wall, y 2.3..3.9 with the late-order slot), the insertion area's parking spots, the
-- delivery zone (right wall, y 2.3..3.3), the corner devices R1, R2, TST and the machines' input,
-- side and look places; robots pass them at the planner's wall margin without touching a puck
-- that lies against the wall.
local SPOTS = {
   {x = 1.40, y = 0.0, ori = -math.pi / 2},   -- bottom wall, between the insertion area and M3
   {x = 4.45, y = 0.0, ori = -math.pi / 2},   -- bottom wall, between M3 and R1
   {x = 5.6, y = 1.30, ori = 0.0},            -- right wall, between R1 and the delivery zone
   {x = 5.6, y = 4.30, ori = 0.0},            -- right wall, between the delivery zone and TST
   {x = 4.45, y = 5.6, ori = math.pi / 2},    -- top wall, between M7 and TST
   {x = 0.0, y = 4.55, ori = math.pi},        -- left wall, between the late-order slot and R2
}
local HELD = 0.2225         -- robot centre to a held puck's centre
local STAND_OFF = 0.2675    -- robot centre to the wall when leaving: the planner keeps 0.26 m
local SLOT = 0.12           -- pucks left at one spot lie this far apart along the wall
local SLOTS = 7             -- ... in this many slots, centred on the spot

local left_at = {}          -- spot index -> pucks this robot left there (kept across calls)

local function robot_number()
   return tonumber(string.match(robot_name, "(%d+)$")) or 1
end

-- The robot pose that leaves the puck in the next free slot of spot i.
local function spot_pose(i)
   local s = SPOTS[i]
   local k = left_at[i] or 0
   local slot = ((robot_number() - 1) + 3 * k) % SLOTS
   local along = (slot - (SLOTS - 1) / 2) * SLOT
   local c, n = math.cos(s.ori), math.sin(s.ori)
   -- Along the wall: perpendicular to the facing.
   local wx, wy = s.x - n * along, s.y + c * along
   return wx - c * STAND_OFF, wy - n * STAND_OFF, s.ori
end

-- Spots by distance from the robot, nearest first.
local function spot_order()
   local x, y = pose:get()
   local order = {}
   for i = 1, #SPOTS do order[#order + 1] = i end
   table.sort(order, function(a, b)
      local ax, ay = spot_pose(a)
      local bx, by = spot_pose(b)
      local da, db = (ax - x) ^ 2 + (ay - y) ^ 2, (bx - x) ^ 2 + (by - y) ^ 2
      if da ~= db then return da < db end
      return a < b
   end)
   return order
end

local function bad_place(self, vars)
   if vars.place ~= nil and vars.place ~= "AWAY" then
      self.fsm.error = string.format("leave_puck: unknown place '%s' (only \"AWAY\")",
                                     tostring(vars.place))
      return true
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"START", JumpState},
   {"CARRY", SkillJumpState, skills={{drive_to}}, final_to="BACK", fail_to="NEXT_SPOT"},
   {"NEXT_SPOT", JumpState},
   {"BACK",  SkillJumpState, skills={{motor_move}}, final_to="CHECK", fail_to="FAILED"},
   {"CHECK", JumpState},
}

fsm:add_transitions{
   {"START", "FAILED", precond=bad_place, desc="bad place"},
   {"START", "BACK", cond="vars.place == nil", desc="leave it here"},
   {"START", "FINAL", cond="not sensor:puck_in_holder()", desc="nothing to leave"},
   {"START", "CARRY", cond=true, desc="carry it away"},
   {"NEXT_SPOT", "FAILED", cond="vars.tried >= 3", desc="no dump spot reached"},
   {"NEXT_SPOT", "CARRY", cond=true, desc="the next spot"},
   {"CHECK", "FINAL", cond="not sensor:puck_in_holder()", desc="puck left"},
   {"CHECK", "FAILED", timeout={0.3, error="leave_puck: the puck is still in the holder"}},
}

function START:init()
   local v = self.fsm.vars
   v.tried = 0
   if v.place == "AWAY" then v.order = spot_order() end
end

function CARRY:init()
   local v = self.fsm.vars
   v.tried = v.tried + 1
   v.spot = v.order[v.tried]
   local x, y, ori = spot_pose(v.spot)
   self.args["drive_to"] = {x = x, y = y, ori = ori, forward_only = true}
end

function NEXT_SPOT:init()
   local e = self.fsm.states.CARRY.error
   if self.fsm.vars.tried >= 3 then
      self.fsm.error = "leave_puck: " .. tostring(e or "no dump spot reached")
      self.fsm.reason = self.fsm.states.CARRY.reason  -- drive_to's, if it gave one
   end
end

function BACK:init()
   local d = self.fsm.vars.distance or 0.25
   self.args["motor_move"] = {x = -d, vel_trans = 0.25}
end

function CHECK:exit()
   local v = self.fsm.vars
   if v.spot ~= nil and not sensor:puck_in_holder() then
      left_at[v.spot] = (left_at[v.spot] or 0) + 1
   end
end
