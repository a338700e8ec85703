-- SPDX-License-Identifier: MIT
-- deliver: bring the held product to the active delivery gate.
name               = "deliver"
fsm                = SkillHSM:new{name=name, start="NEXT_GATE"}
depends_skills     = {"drive_to", "motor_move"}
depends_interfaces = {
   {v = "navigator", type = "NavigatorInterface", id = "Navigator"},
   {v = "pose",      type = "Position3DInterface", id = "Pose"},
   {v = "sensor",    type = "RobotinoSensorInterface", id = "Robotino"},
   {v = "light",     type = "RobotinoLightInterface", id = "Light"},
}
documentation      = [==[Delivers the held product (P1, P2 or P3): looks at the delivery gates one
after another (nearest first) until one shows green (the active gate), puts the puck under its
reader, waits until the gate has processed it (green + yellow, then all three lamps or the
referee taking the puck away), and backs away. Result: "DELIVERED D2".
@param gate    "D1", "D2" or "D3" to try that gate first (default: the nearest)
@param rounds  how many times to look at all three gates before giving up (default 3)
Fails: "deliver: no puck in the holder", "deliver: no active gate (D1 R, D2 R, D3 R)",
"D2 refused the puck (yellow blinking: no active order for it)", "D2 went inactive before the
delivery", "D2: no delivery light within 10 s", drive_to's failure.
]==]

local GATES = {"D1", "D2", "D3"}

local function order(vars)
   local x, y = pose:get()
   local list = {}
   for _, g in ipairs(GATES) do list[#list + 1] = g end
   local first = vars.gate
   table.sort(list, function(a, b)
      if a == first then return true elseif b == first then return false end
      local ax, ay = navigator:place(a .. "_look")
      local bx, by = navigator:place(b .. "_look")
      return (ax - x) ^ 2 + (ay - y) ^ 2 < (bx - x) ^ 2 + (by - y) ^ 2
   end)
   return list
end

local function code(gate)
   if not light:visible() or light:device() ~= gate then return nil end
   local function lamp(v, ch)
      if v == light.ON then return ch elseif v == light.BLINKING then return ch:lower() end
      return ""
   end
   return lamp(light:red(), "R") .. lamp(light:yellow(), "Y") .. lamp(light:green(), "G")
end

local function read(self, vars)
   local c = code(vars.current)
   if c ~= nil and light:stable_for() >= 0.6 then
      vars.seen[#vars.seen + 1] = vars.current .. " " .. (c == "" and "off" or c)
      vars.active = c == "G"
      return true
   end
   if clock.now() - vars.read_since >= 4.0 then
      vars.seen[#vars.seen + 1] = vars.current .. " unseen"
      vars.active = false
      return true
   end
   return false
end

local function exhausted(self, vars)
   if vars.index < #vars.gates * (vars.rounds or 3) then return false end
   self.fsm.error = "deliver: no active gate (" .. table.concat(vars.seen, ", ") .. ")"
   return true
end

local function watch(self, vars)
   local c = code(vars.current)
   local now = clock.now()
   if c == "YG" then vars.processing = true end
   -- Delivered: all three lamps, or the referee took the puck after the gate processed it.
   if c == "RYG" then return true end
   if vars.processing and not sensor:puck_in_holder() then return true end
   if c ~= nil and string.find(c, "y") and light:stable_for() >= 0.6 then
      self.fsm.error = vars.current .. " refused the puck (yellow blinking: no active order for it)"
      return true
   end
   if c == "R" and light:stable_for() >= 1.5 then
      self.fsm.error = vars.current .. " went inactive before the delivery"
      return true
   end
   if now - vars.put_at >= 10.0 then
      self.fsm.error = vars.current .. ": no delivery light within 10 s"
      return true
   end
   return false
end

fsm:define_states{ export_to=_M,
   {"NEXT_GATE", JumpState},
   {"GOTO_LOOK", SkillJumpState, skills={{drive_to}}, final_to="READ", fail_to="NEXT_GATE"},
   {"READ",      JumpState},
   {"PUT",       SkillJumpState, skills={{drive_to}}, final_to="WAIT", fail_to="FAILED"},
   {"WAIT",      JumpState},
   {"BACK_OFF",  SkillJumpState, skills={{motor_move}}, final_to="FINAL", fail_to="FINAL"},
}

fsm:add_transitions{
   {"NEXT_GATE", "FAILED", precond="not sensor:puck_in_holder()",
    error="deliver: no puck in the holder"},
   {"NEXT_GATE", "FAILED", cond=exhausted, desc="no gate"},
   {"NEXT_GATE", "GOTO_LOOK", cond=true},
   {"READ", "PUT", cond="vars.read_done and vars.active", desc="active gate"},
   {"READ", "NEXT_GATE", cond="vars.read_done", desc="not this one"},
   {"WAIT", "BACK_OFF", cond=function(self, vars) return watch(self, vars) and not self.fsm.error end,
    desc="delivered"},
}

function NEXT_GATE:init()
   local v = self.fsm.vars
   v.gates = v.gates or order(v)
   v.seen = v.seen or {}
   v.index = (v.index or 0)
end

function GOTO_LOOK:init()
   local v = self.fsm.vars
   v.index = v.index + 1
   v.current = v.gates[(v.index - 1) % #v.gates + 1]
   self.args["drive_to"] = {place = v.current .. "_look", forward_only = true}
end

function READ:init()
   self.fsm.vars.read_since = clock.now()
   self.fsm.vars.read_done = false
end

function READ:loop()
   local v = self.fsm.vars
   if not v.read_done then v.read_done = read(self, v) end
end

function PUT:init()
   self.args["drive_to"] = {place = self.fsm.vars.current .. "_input", forward_only = true}
end

function WAIT:init()
   self.fsm.vars.put_at = clock.now()
   self.fsm.vars.processing = false
end

function BACK_OFF:init()
   self.fsm.result = "DELIVERED " .. self.fsm.vars.current
   self.args["motor_move"] = {x = -0.25, vel_trans = 0.25}
end
