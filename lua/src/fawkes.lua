-- SPDX-License-Identifier: MIT
-- The Fawkes compatibility layer (docs/fawkes.md, "Skills written for Fawkes"): what a skill
-- written for Fawkes' Lua skiller (2013) finds besides the skill DSL -- the blackboard's
-- interface objects with Fawkes' generated API (read, has_writer, msgq_enqueue_copy, field
-- accessors, messages, constants), fawkes.Time, fawkes.tf and the tf transformer `tf`,
-- fawkes.load_yaml_navgraph, the `config` object and the built-in modules `require` knows.
-- Written for llsfsim from Fawkes' documented behaviour and interface definitions.
-- Embedded into llsf_lua and run once per interpreter before the prelude, which gets the
-- returned table as native.fawkes.
local native = ...

local fmt, floor, sqrt, atan2 = string.format, math.floor, math.sqrt, math.atan
local sin, cos, abs = math.sin, math.cos, math.abs
local type, pairs, ipairs, tostring, error = type, pairs, ipairs, tostring, error
local setmetatable, rawget, select = setmetatable, rawget, select
local now_ns = native.now_ns
local llsf = native.interfaces  -- llsfsim's own interface objects (pose, navigator, ...)

local F = {}

-- Errors at the skill's line: `level` 2 is the caller of the function that raises.
local function fail(level, msg, ...)
  error(fmt(msg, ...), level + 1)
end

-- fawkes.Time ------------------------------------------------------------------------------
-- Simulated time (Fawkes' clock was the robot's; llsfsim's is the game's simulated clock).
local Time = {}
Time.__index = Time
Time.__metatable = false
local function time_of(ns) return setmetatable({ns = ns}, Time) end
-- Time:new() is now; Time:new(sec, usec) that time; Time:new(t) a copy of t.
function Time.new(_, sec, usec)
  if sec == nil then return time_of(now_ns()) end
  if type(sec) == "table" and rawget(sec, "ns") then return time_of(sec.ns) end
  if type(sec) ~= "number" then fail(2, "fawkes.Time:new: expected seconds (a number)") end
  return time_of(floor(sec * 1e9 + (usec or 0) * 1e3 + 0.5))
end
function Time:in_sec() return self.ns / 1e9 end
function Time:in_msec() return self.ns / 1e6 end
function Time:in_usec() return self.ns / 1e3 end
function Time:get_sec() return self.ns // 1000000000 end
function Time:get_usec() return (self.ns % 1000000000) // 1000 end
function Time:stamp() self.ns = now_ns(); return self end
function Time:set_time(sec, usec) self.ns = floor(sec * 1e9 + (usec or 0) * 1e3 + 0.5) end
-- As Fawkes' Time: t1 - t2 is the difference in seconds; t + secs and t - secs are times.
Time.__sub = function(a, b)
  if type(b) == "number" then return time_of(a.ns - floor(b * 1e9 + 0.5)) end
  return (a.ns - b.ns) / 1e9
end
Time.__add = function(a, b)
  if type(b) == "number" then return time_of(a.ns + floor(b * 1e9 + 0.5)) end
  return time_of(a.ns + b.ns)
end
Time.__lt = function(a, b) return a.ns < b.ns end
Time.__le = function(a, b) return a.ns <= b.ns end
Time.__eq = function(a, b) return a.ns == b.ns end
Time.__tostring = function(t) return fmt("%.6f", t.ns / 1e9) end

-- fawkes.tf: the 2D part of tf's (Bullet's) math -----------------------------------------------
local Vector3 = {}
Vector3.__index = Vector3
Vector3.__metatable = false
function Vector3.new(_, x, y, z) return setmetatable({x_ = x or 0, y_ = y or 0, z_ = z or 0}, Vector3) end
function Vector3:x() return self.x_ end
function Vector3:y() return self.y_ end
function Vector3:z() return self.z_ end
function Vector3:length() return sqrt(self.x_ ^ 2 + self.y_ ^ 2 + self.z_ ^ 2) end

local Quaternion = {}
Quaternion.__index = Quaternion
Quaternion.__metatable = false
-- Quaternion:new(x, y, z, w), Quaternion:new(yaw, pitch, roll) or Quaternion:new() (identity).
function Quaternion.new(_, a, b, c, d)
  if d ~= nil then return setmetatable({x_ = a, y_ = b, z_ = c, w_ = d}, Quaternion) end
  local yaw, pitch, roll = a or 0, b or 0, c or 0
  local cy, sy = cos(yaw / 2), sin(yaw / 2)
  local cp, sp = cos(pitch / 2), sin(pitch / 2)
  local cr, sr = cos(roll / 2), sin(roll / 2)
  return setmetatable({x_ = sr * cp * cy - cr * sp * sy, y_ = cr * sp * cy + sr * cp * sy,
                       z_ = cr * cp * sy - sr * sp * cy, w_ = cr * cp * cy + sr * sp * sy},
                      Quaternion)
end
function Quaternion:x() return self.x_ end
function Quaternion:y() return self.y_ end
function Quaternion:z() return self.z_ end
function Quaternion:w() return self.w_ end
local function get_yaw(q)
  if type(q) ~= "table" or type(q.w_) ~= "number" then
    fail(2, "fawkes.tf.get_yaw: expected a Quaternion")
  end
  return atan2(2 * (q.w_ * q.z_ + q.x_ * q.y_), 1 - 2 * (q.y_ * q.y_ + q.z_ * q.z_))
end
function Quaternion:getAngle() return 2 * math.acos(math.max(-1, math.min(1, self.w_))) end

local Pose = {}
Pose.__index = Pose
Pose.__metatable = false
-- Pose:new(rotation, origin) (tf::Pose is a Transform of a Quaternion and a Vector3).
function Pose.new(_, q, v)
  return setmetatable({q = q or Quaternion:new(0, 0, 0, 1), v = v or Vector3:new()}, Pose)
end
function Pose:getOrigin() return self.v end
function Pose:getRotation() return self.q end
function Pose:setOrigin(v) self.v = v end
function Pose:setRotation(q) self.q = q end

local StampedPose = setmetatable({}, {__call = function(cls, ...) return cls.new(cls, ...) end})
StampedPose.__index = StampedPose
StampedPose.__metatable = false
-- StampedPose:new() (empty) or StampedPose(pose, time, frame_id) / StampedPose:new(...).
function StampedPose.new(_, pose, stamp, frame)
  local p = pose or Pose:new()
  return setmetatable({q = p.q, v = p.v, stamp = stamp or Time:new(0, 0), frame_id = frame or ""},
                      StampedPose)
end
StampedPose.getOrigin, StampedPose.getRotation = Pose.getOrigin, Pose.getRotation
StampedPose.setOrigin, StampedPose.setRotation = Pose.setOrigin, Pose.setRotation

local tf = {Vector3 = Vector3, Quaternion = Quaternion, Pose = Pose, StampedPose = StampedPose,
            Point = Vector3, get_yaw = get_yaw,
            create_quaternion_from_yaw = function(yaw) return Quaternion:new(yaw, 0, 0) end}

-- The robot's frames: /map (the pose estimate's frame), /odom (the same frame here: llsfsim has
-- no odometry apart from localization) and /base_link (the robot: x forward, y left).
-- (by name, with or without the leading slash: a look-up, no pattern matched per transform)
local frame_kinds = {map = "world", ["/map"] = "world", odom = "world", ["/odom"] = "world",
                     base_link = "robot", ["/base_link"] = "robot"}
local function frame_kind(name)
  if type(name) ~= "string" then return nil end
  return frame_kinds[name]
end
local function robot_pose()
  return llsf.Position3DInterface.get(llsf.Position3DInterface)
end
-- (x, y, yaw) in frame `from` as (x, y, yaw) in frame `to`.
local function transform2d(x, y, yaw, from, to)
  local kf, kt = frame_kind(from), frame_kind(to)
  if kf == kt then return x, y, yaw end
  local rx, ry, ra = robot_pose()
  local c, s = cos(ra), sin(ra)
  if kf == "robot" then  -- robot -> world
    return rx + c * x - s * y, ry + s * x + c * y, yaw + ra
  end
  local dx, dy = x - rx, y - ry  -- world -> robot
  local a = (yaw - ra + math.pi) % (2 * math.pi) - math.pi
  return c * dx + s * dy, -s * dx + c * dy, a
end
F.transform2d = transform2d

-- The transformer skills see as the global `tf` (Fawkes' tf listener).
local transformer = {}
function transformer.can_transform(_, target, source)
  return frame_kind(target) ~= nil and frame_kind(source) ~= nil
end
function transformer.frame_exists(_, frame) return frame_kind(frame) ~= nil end
function transformer.transform_pose(_, target, stamped_in, stamped_out)
  local function stamped(p) return type(p) == "table" and p.frame_id ~= nil and p.v ~= nil end
  if not stamped(stamped_in) or not stamped(stamped_out) then
    fail(2, "tf:transform_pose(target_frame, stamped_in, stamped_out): expected StampedPoses")
  end
  for i = 1, 2 do  -- the target, then the pose's frame
    local f = stamped_in.frame_id
    if i == 1 then f = target end
    if not frame_kind(f) then
      fail(2, "tf:transform_pose: unknown frame '%s' (llsfsim has /map, /odom and /base_link)",
           tostring(f))
    end
  end
  local x, y, yaw = transform2d(stamped_in.v.x_, stamped_in.v.y_, get_yaw(stamped_in.q),
                                stamped_in.frame_id, target)
  stamped_out.v = Vector3:new(x, y, stamped_in.v.z_)
  stamped_out.q = Quaternion:new(yaw, 0, 0)
  stamped_out.frame_id = target
  stamped_out.stamp = Time:new()
end
F.tf_transformer = transformer

-- fawkes.load_yaml_navgraph --------------------------------------------------------------------
local Node = {}
Node.__index = Node
Node.__metatable = false
-- Graphs and their nodes are read-only for skills (F.readonly, the prelude's: below, when a graph
-- is loaded): every graph loaded goes into the one list ppgoto's places come from, so one skill
-- could otherwise move another's place.
local invalid_node = setmetatable({name_ = "", x_ = 0, y_ = 0, props = {}, reach = {}}, Node)
local invalid_shown  -- invalid_node as skills get it (made with the first graph)
function Node:name() return self.name_ end
function Node:x() return self.x_ end
function Node:y() return self.y_ end
function Node:is_valid() return self.name_ ~= "" end
function Node:is_unconnected() return self.unconnected == true end
function Node:has_property(p) return self.props[p] ~= nil end
function Node:has_properties()
  local step, t = pairs(self.props)  -- (a read-only proxy: next() would see it empty)
  return step(t) ~= nil
end
function Node:property(p) return self.props[p] or "" end
function Node:property_as_float(p) return tonumber(self.props[p]) or 0.0 end
function Node:property_as_int(p) return floor(tonumber(self.props[p]) or 0) end
function Node:property_as_bool(p) return self.props[p] == "true" end
function Node:properties()
  local t = {}
  for k, v in pairs(self.props) do t[k] = v end
  return t
end
function Node:reachable_nodes()
  local t = {}
  for i, n in ipairs(self.reach) do t[i] = n end
  return t
end

local Graph = {}
Graph.__index = Graph
Graph.__metatable = false
function Graph:name() return self.name_ end
function Graph:nodes()
  local t = {}
  for i, n in ipairs(self.list) do t[i] = n end
  return t
end
-- The node of that name, or an invalid node (name "", is_valid() false), as Fawkes returned.
function Graph:node(name) return self.by_name[name] or invalid_shown end
function Graph:root_node() return self.by_name[self.root] or invalid_shown end
function Graph:node_exists(name) return self.by_name[name] ~= nil end
function Graph:search_nodes(property)
  local t = {}
  for _, n in ipairs(self.list) do
    if property == nil or property == "" or n.props[property] ~= nil then t[#t + 1] = n end
  end
  return t
end
-- As Fawkes' TopologicalMapGraph (2013): the closest node with `property` ("" any), skipping
-- nodes tagged !unconnected unless asked to; closest_node_to skips the named node itself and,
-- when no other node qualifies, returns the first candidate (Fawkes' search started from it).
local function closest(g, x, y, property, unconnected, except)
  local nodes = g:search_nodes(property)
  local best, best_d = nodes[1], math.huge
  for _, n in ipairs(nodes) do
    if (unconnected or not n.unconnected) and n.name_ ~= except then
      local d = sqrt((n.x_ - x) ^ 2 + (n.y_ - y) ^ 2)
      if d < best_d then best, best_d = n, d end
    end
  end
  return best or invalid_shown
end
function Graph:closest_node(x, y, property) return closest(self, x, y, property, false) end
function Graph:closest_node_with_unconnected(x, y, property)
  return closest(self, x, y, property, true)
end
function Graph:closest_node_to(name, property)
  local n = self:node(name)
  return closest(self, n.x_, n.y_, property, false, name)
end
function Graph:closest_node_to_with_unconnected(name, property)
  local n = self:node(name)
  return closest(self, n.x_, n.y_, property, true, name)
end

local graphs = {}  -- every graph loaded in this interpreter (ppgoto's places come from them)
local function load_yaml_navgraph(file)
  if type(file) ~= "string" then fail(2, "fawkes.load_yaml_navgraph: expected a file name") end
  local data, err = native.navgraph(file)
  if not data then fail(2, "fawkes.load_yaml_navgraph: %s", err) end
  local readonly = F.readonly
  local what = "navgraph " .. tostring(data.name)
  if not invalid_shown then invalid_shown = readonly(invalid_node, "navgraph node") end
  local nodes, reach = {}, {}
  for i, d in ipairs(data.nodes) do
    reach[d.name] = {}
    nodes[i] = setmetatable({name_ = d.name, x_ = d.x, y_ = d.y,
                             props = readonly(d.properties, what .. " node " .. d.name),
                             unconnected = d.unconnected,
                             reach = readonly(reach[d.name], what .. " node " .. d.name)}, Node)
  end
  for _, e in ipairs(data.edges) do
    local a, b = reach[e[1]], reach[e[2]]
    a[#a + 1] = e[2]
    if not e[3] then b[#b + 1] = e[1] end
  end
  local list, by_name = {}, {}
  for i, n in ipairs(nodes) do
    list[i] = readonly(n, what .. " node " .. n.name_)
    by_name[n.name_] = list[i]
  end
  local g = readonly(setmetatable({name_ = data.name, root = data.root,
                                   list = readonly(list, what), by_name = readonly(by_name, what)},
                                  Graph), what)
  graphs[#graphs + 1] = g
  return g
end
-- The node `name` of the graphs loaded so far (the first that has it), or nil.
function F.navgraph_node(name)
  for _, g in ipairs(graphs) do
    local n = g.by_name[name]
    if n then return n end
  end
  return nil
end

-- config -----------------------------------------------------------------------------------
-- Fawkes' configuration as skills read it (skills.fawkes_config of the scenario).
local values = native.fawkes_config
local config = {}
local function value_of(path, what)
  local v = values[path]
  if v == nil then
    fail(3, "config:%s(\"%s\"): no such value (set it under skills.fawkes_config of the " ..
            "scenario)", what, tostring(path))
  end
  return v
end
function config.exists(_, path) return values[path] ~= nil end
function config.get_string(_, path) return value_of(path, "get_string") end
function config.get_float(_, path)
  local v = tonumber(value_of(path, "get_float"))
  if not v then fail(2, "config:get_float(\"%s\"): '%s' is not a number", path, values[path]) end
  return v
end
function config.get_int(_, path)
  local v = math.tointeger(tonumber(value_of(path, "get_int")))
  if not v then fail(2, "config:get_int(\"%s\"): '%s' is not an integer", path, values[path]) end
  return v
end
config.get_uint = config.get_int
function config.get_bool(_, path)
  local v = value_of(path, "get_bool")
  if v == "true" or v == "True" or v == "TRUE" then return true end
  if v == "false" or v == "False" or v == "FALSE" then return false end
  fail(2, "config:get_bool(\"%s\"): '%s' is not true or false", path, v)
end
function config.is_float(_, path) return tonumber(values[path]) ~= nil end
function config.is_bool(_, path)
  local v = values[path]
  return v == "true" or v == "false"
end
function config.is_string(_, path) return values[path] ~= nil end
F.config = config

-- The blackboard ---------------------------------------------------------------------------
-- One object per interface (type and id), as the skiller opened them. Fields are read from the
-- robot (RobotApi, at the profile's sensor rates) when first read in a cycle or on read();
-- messages are processed at once, in msgq_enqueue_copy, which returns the message's id.
local cycle_ns = native.cycle_ns or 33333333

-- Interface types: fields (name -> {kind, length}), constants, enum values, messages (name ->
-- field names in order), the default id (llsfsim's own skills name no id), and the writer.
local types = {}
local function def(type_name, t) types[type_name] = t end

local LIGHT = {ON = "ON", OFF = "OFF", BLINKING = "BLINKING", UNKNOWN = "UNKNOWN"}
local function lamp(state, now)  -- a lamp of a LightReading as a switch sees it (lit or not)
  if state == "ON" then return true end
  if state == "BLINKING" then return (now // 250000000) % 2 == 0 end  -- 2 Hz, as the refbox
  return false
end

-- visibility_history as Fawkes' vision plugins count it: cycles seen in a row (positive) or
-- not seen (negative), here from the time since the visibility last changed.
local function history(d, visible, now)
  now = now or now_ns()
  if d.vis_state ~= visible then d.vis_state, d.vis_since = visible, now end
  local n = (now - d.vis_since) // cycle_ns + 1
  return visible and n or -n
end

-- (the arrays are filled in place: this runs for every polled interface in every cycle)
local function pose_fields(d, x, y, yaw, frame, visible, now)
  local t, r = d.translation, d.rotation
  t[1], t[2], t[3] = x, y, 0.0
  r[1], r[2], r[3], r[4] = 0.0, 0.0, sin(yaw / 2), cos(yaw / 2)
  d.frame = frame
  d.visibility_history = history(d, visible, now)
end

-- The puck detection's sightings nearest first ({x, y, squared distance}), once per time stamp:
-- every OmniPuck<n> of every skill reads the same list.
local puck_list, puck_list_ns = {}, -1
local function by_distance(a, b) return a[3] < b[3] end
local function pucks_by_distance(now)
  if puck_list_ns == now then return puck_list end
  local V = llsf.PuckVisionInterface
  local list = {}
  for i = 1, V.count(V) do
    local px, py = V.puck(V, i)
    list[#list + 1] = {px, py, px * px + py * py}
  end
  table.sort(list, by_distance)
  puck_list, puck_list_ns = list, now
  return list
end

def("Position3DInterface", {
  default_id = "Pose",
  fields = {frame = {"string"}, visibility_history = {"int32"}, rotation = {"double", 4},
            translation = {"double", 3}},
  messages = {},
  -- Pose: the localization; OmniPuck<n>: the n-th nearest puck the puck detection sees;
  -- "Euclidean Laser Cluster": the signal of the device in front (its RFID zone), as the
  -- laser-cluster plugin found it, while the light detection sees that device.
  -- (the second function: whether the data are visible now, all that F.poll needs of them)
  writer = function(id)
    if id == "Pose" then
      local P = llsf.Position3DInterface
      return function(d, now)
        local x, y, a = P.get(P)
        pose_fields(d, x, y, a, "/map", P.is_valid(P), now)
      end, function() return P.is_valid(P) end
    end
    local n = id:match("^OmniPuck(%d+)$")
    if n then
      n = tonumber(n)
      local V = llsf.PuckVisionInterface
      return function(d, now)
        local list = pucks_by_distance(now)
        local p = list[n]
        pose_fields(d, p and p[1] or 0.0, p and p[2] or 0.0, 0.0, "/base_link", p ~= nil, now)
      end, function() return V.count(V) >= n end, n
    end
    if id == "Euclidean Laser Cluster" then
      local L, N = llsf.RobotinoLightInterface, llsf.NavigatorInterface
      local function target()  -- the RFID zone of the device the light detection sees
        local device = L.visible(L) and L.device(L) or nil
        if not device then return nil end
        local _, _, _, tx, ty = N.place(N, device)
        return tx, ty
      end
      return function(d, now)
        local tx, ty = target()
        local x, y
        if tx then x, y = transform2d(tx, ty, 0, "/map", "/base_link") end
        pose_fields(d, x or 0.0, y or 0.0, 0.0, "/base_link", x ~= nil, now)
      end, function() return target() ~= nil end
    end
    return nil
  end,
  llsf = llsf.Position3DInterface,
})

def("RobotinoLightInterface", {
  default_id = "Light_State",
  aliases = {Light = true},
  fields = {red = {"LightState"}, yellow = {"LightState"}, green = {"LightState"},
            visibility_history = {"int32"}, ready = {"bool"}},
  constants = LIGHT,
  messages = {},
  -- Light_State: the light detection of the device in front (profile: ground truth or vision).
  -- Other ids (the team's "Light determined") are written by skills (writing=true).
  writer = function(id)
    if id ~= "Light_State" then return nil end
    local LI = llsf.RobotinoLightInterface
    return function(d, now)
      local L = LI
      local visible = L.visible(L)
      d.red = visible and L.red(L) or "UNKNOWN"
      d.yellow = visible and L.yellow(L) or "UNKNOWN"
      d.green = visible and L.green(L) or "UNKNOWN"
      d.ready = visible
      -- (frames since the reading last changed, as the agent's "Light_State" counts them)
      local h = history(d, visible, now)
      d.visibility_history = visible and (floor(L.stable_for(L) * 1e9) // cycle_ns + 1) or h
    end, function() return LI.visible(LI) end
  end,
  llsf = llsf.RobotinoLightInterface,
})

def("RobotinoAmpelInterface", {
  fields = {state = {"AmpelState"}},
  constants = {YELLOW = "YELLOW", GREEN = "GREEN", RED = "RED", YELLOW_FLASHING = "YELLOW_FLASHING",
               NO_CHANGE = "NO_CHANGE"},
  messages = {},
  writer = function() return nil end,  -- written by skills (the team's determine_signal)
})

def("SwitchInterface", {
  fields = {enabled = {"bool"}, value = {"float"}, history = {"float"},
            short_activations = {"uint32"}, long_activations = {"uint32"},
            activation_count = {"uint32"}},
  messages = {SetMessage = {"enabled", "value"}, EnableSwitchMessage = {},
              DisableSwitchMessage = {}, EnableDurationMessage = {"duration"}},
  -- ampel_red, ampel_orange, ampel_green: whether the light detection sees that lamp lit (a
  -- blinking lamp in its lit half-period); the other switches (vision and laser plugins, the
  -- motor switch) hold what the skills set: llsfsim's perception always runs.
  writer = function(id)
    local colour = ({ampel_red = "red", ampel_orange = "yellow", ampel_green = "green"})[id]
    if colour then
      return function(d, now)
        local L = llsf.RobotinoLightInterface
        d.enabled = L.visible(L) and lamp(L[colour](L), now) or false
        d.value = d.enabled and 1.0 or 0.0
      end
    end
    return "store"
  end,
  handle = function(d, name, m)
    if name == "EnableSwitchMessage" then d.enabled = true
    elseif name == "DisableSwitchMessage" then d.enabled = false
    elseif name == "SetMessage" then d.enabled, d.value = m.enabled == true, m.value or 0.0
    elseif name == "EnableDurationMessage" then d.enabled = true end
    if d.enabled then d.activation_count = (d.activation_count or 0) + 1 end
  end,
})

def("LaserClusterInterface", {
  fields = {max_x = {"float"}},
  messages = {SetMaxXMessage = {"max_x"}},
  writer = function() return "store" end,
  handle = function(d, name, m)
    if name == "SetMaxXMessage" then d.max_x = m.max_x or 0.0 end
  end,
})

def("RobotinoSensorInterface", {
  default_id = "Robotino",
  fields = {mot_velocity = {"float", 3}, mot_position = {"int32", 3}, mot_current = {"float", 3},
            bumper = {"bool"}, distance = {"float", 9}, digital_in = {"bool", 8},
            analog_in = {"float", 8}, gyro_available = {"bool"}, gyro_angle = {"float"},
            gyro_rate = {"float"}},
  messages = {},
  -- distance[8]: the puck holder's IR distance (m; 0: nothing in range); analog_in[0] and [4]:
  -- the right and left optical sensors (0 V while they see, 10 V otherwise). The other
  -- sensors of the Robotino are not simulated (0).
  writer = function(id)
    if id ~= "Robotino" then return nil end
    return function(d)
      local S = llsf.RobotinoSensorInterface
      d.distance[9] = S.ir_distance(S)
      local an = d.analog_in
      for i = 1, 8 do an[i] = 10 end
      an[1] = S.optical_right(S) and 0 or 10
      an[5] = S.optical_left(S) and 0 or 10
    end
  end,
  llsf = llsf.RobotinoSensorInterface,
})

def("MotorInterface", {
  default_id = "Robotino",
  fields = {motor_state = {"uint32"}, drive_mode = {"uint32"}, right_rpm = {"int32"},
            rear_rpm = {"int32"}, left_rpm = {"int32"}, odometry_path_length = {"float"},
            odometry_position_x = {"float"}, odometry_position_y = {"float"},
            odometry_orientation = {"float"}, vx = {"float"}, vy = {"float"}, omega = {"float"},
            controller = {"uint32"}, controller_thread_name = {"string"}},
  constants = {MOTOR_ENABLED = 0, MOTOR_DISABLED = 1, DRIVE_MODE_RPM = 1, DRIVE_MODE_TRANS = 2,
               DRIVE_MODE_ROT = 3, DRIVE_MODE_TRANS_ROT = 4, DRIVE_MODE_ORBIT = 5,
               DRIVE_MODE_LINE_TRANS_ROT = 6},
  messages = {AcquireControlMessage = {"controller", "controller_thread_name"},
              TransRotMessage = {"vx", "vy", "omega"}, TransMessage = {"vx", "vy"},
              RotMessage = {"omega"}, SetMotorStateMessage = {"motor_state"},
              ResetOdometryMessage = {}},
  -- The odometry fields hold the pose estimate (llsfsim has no odometry of its own).
  writer = function(id)
    if id ~= "Robotino" then return nil end
    return function(d)
      local P = llsf.Position3DInterface
      local x, y, a = P.get(P)
      d.odometry_position_x, d.odometry_position_y, d.odometry_orientation = x, y, a
    end
  end,
  handle = function(d, name, m)
    local M = llsf.MotorInterface
    if name == "AcquireControlMessage" then
      d.controller, d.controller_thread_name = m.controller or 0, m.controller_thread_name or ""
    elseif name == "TransRotMessage" or name == "TransMessage" or name == "RotMessage" then
      d.vx, d.vy, d.omega = m.vx or 0.0, m.vy or 0.0, m.omega or 0.0
      d.drive_mode = 4
      M.set_velocity(M, d.vx, d.vy, d.omega)
    elseif name == "SetMotorStateMessage" then
      d.motor_state = m.motor_state or 0
    end
  end,
  llsf = llsf.MotorInterface,
})

local NAV_ERRORS = {ERROR_NONE = 0, ERROR_MOTOR = 1, ERROR_OBSTRUCTION = 2,
                    ERROR_UNKNOWN_PLACE = 4}
def("NavigatorInterface", {
  default_id = "Pathplan",
  llsf_first = {Navigator = true},  -- llsfsim's own skills name their navigator so
  fields = {flags = {"uint32"}, x = {"float"}, y = {"float"}, dest_x = {"float"},
            dest_y = {"float"}, dest_ori = {"float"}, dest_dist = {"float"}, msgid = {"uint32"},
            final = {"bool"}, error_code = {"uint32"}, max_velocity = {"float"},
            security_distance = {"float"}, escaping_enabled = {"bool"}},
  constants = NAV_ERRORS,
  messages = {StopMessage = {}, CartesianGotoMessage = {"x", "y", "orientation"},
              PolarGotoMessage = {"phi", "dist", "orientation"}, PlaceGotoMessage = {"place"},
              TurnMessage = {"angle", "velocity"}},
  -- Both ids drive llsfsim's navigator: "Pathplan" (Fawkes' navgraph/pathplan, ppgoto) takes
  -- goals in /map, "Navigator" (the team's relgoto) in /base_link. A place is a node of a
  -- navgraph loaded with fawkes.load_yaml_navgraph (its pos and orientation property) or else
  -- an llsfsim place. msgid is the navigator's goal id; final: arrived or failed.
  writer = function(id)
    if id ~= "Pathplan" and id ~= "Navigator" then return nil end
    return function(d)
      local N = llsf.NavigatorInterface
      local status = N.status(N)
      d.msgid = N.msgid(N)
      d.final = status ~= "RUNNING" and status ~= "IDLE"
      d.error_code = (status == "INVALID_GOAL" and 4) or
                     ((status == "NO_PATH" or status == "BLOCKED" or status == "STUCK") and 2) or
                     (status == "ABORTED" and 1) or 0
    end
  end,
  -- "Pathplan" drives forward only: the team's move_base (TrajectoryPlannerROS, min_vel_x 0.1
  -- in cfg/move_base_robotino) never drove backwards, so a puck in the holder stays there;
  -- "Navigator" (the relative navigator) may back up.
  handle = function(d, name, m, id, level)
    local N = llsf.NavigatorInterface
    local rel = id == "Navigator"
    local forward = not rel
    local function go(x, y, ori)
      if rel then x, y, ori = transform2d(x, y, ori, "/base_link", "/map") end
      d.dest_x, d.dest_y, d.dest_ori = x, y, ori
      N.goto_pose(N, x, y, ori, forward)
    end
    if name == "StopMessage" then
      N.stop(N)
    elseif name == "CartesianGotoMessage" then
      go(m.x or 0.0, m.y or 0.0, m.orientation or 0.0)
    elseif name == "PolarGotoMessage" then
      local phi, dist = m.phi or 0.0, m.dist or 0.0
      if rel then
        go(dist * cos(phi), dist * sin(phi), m.orientation or 0.0)
      else
        local x, y, a = robot_pose()
        N.goto_pose(N, x + dist * cos(a + phi), y + dist * sin(a + phi), m.orientation or 0,
                    forward)
      end
    elseif name == "PlaceGotoMessage" then
      local place = m.place
      if type(place) ~= "string" then fail(level, "PlaceGotoMessage needs a place (a string)") end
      local node = F.navgraph_node(place)
      if node then
        local ori = node.props.orientation and tonumber(node.props.orientation)
        if not ori then local _, _, a = robot_pose(); ori = a end
        d.dest_x, d.dest_y, d.dest_ori = node.x_, node.y_, ori
        N.goto_pose(N, node.x_, node.y_, ori, forward)
      else
        N.goto_place(N, place, forward)
      end
    elseif name == "TurnMessage" then
      local x, y, a = robot_pose()
      N.goto_pose(N, x, y, a + (m.angle or 0.0), forward)
    end
    return N.msgid(N)
  end,
  llsf = llsf.NavigatorInterface,
})

def("SkillerInterface", {
  default_id = "Skiller",
  fields = {skill_string = {"string"}, error = {"string"}, exclusive_controller = {"uint32"},
            msgid = {"uint32"}, status = {"SkillStatusEnum"}},
  constants = {S_INACTIVE = 0, S_FINAL = 1, S_RUNNING = 2, S_FAILED = 3},
  enums = {status = {[0] = "S_INACTIVE", "S_FINAL", "S_RUNNING", "S_FAILED"}},  -- (the agent's)
  messages = {},  -- skill strings come from the agent (llsfsim's skill runner), not from skills
  -- The skill string the agent sent, its status and error (the engine's own state).
  writer = function(id)
    if id ~= "Skiller" then return nil end
    return function(d)
      d.skill_string, d.status, d.error = native.skiller()
    end
  end,
})

-- Interface objects ------------------------------------------------------------------------
local objects = {}    -- uid -> object
local data_of = {}    -- object -> its data (fields; refreshed from the writer)
local meta_of = {}    -- object -> {type=, id=, t=, write=, stamp=, msgid=}
local message_classes = {}  -- type -> message name -> class
local message_of = setmetatable({}, {__mode = "k"})  -- message -> its class
-- message -> its field values: kept beside it, so that msg:x() is the getter (Fawkes' API) and
-- not hidden by the value
local values_of = setmetatable({}, {__mode = "k"})

local function default_value(kind, len)
  local v = (kind == "string" and "") or (kind == "bool" and false) or
            ((kind == "LightState") and "UNKNOWN") or ((kind == "AmpelState") and "NO_CHANGE") or 0
  if not len then return v end
  local t = {}
  for i = 1, len do t[i] = v end
  return t
end

-- The fields, read again from the robot when the time or what the skills did changed since
-- the object's last read: a command sent in the same cycle (a message, a field set, llsfsim's
-- own methods) shows at once, e.g. the navigator's goal id. `epoch` counts those commands.
local epoch = 0
local function refresh(obj)
  local m = meta_of[obj]
  if m.write then
    local now = now_ns()
    if m.read_ns ~= now or m.read_epoch ~= epoch then
      m.write(data_of[obj], now)
      m.read_ns, m.read_epoch = now, epoch
    end
  end
  return data_of[obj]
end


-- A message class (iface.SomeMessage) is one table for every skill of the robot: skills get it
-- read-only (F.readonly, the prelude's, which also refuses rawset), and neither the messages'
-- metatable nor the interface definition's field list is a field of it.
F.readonly = nil  -- set by the prelude: function(t, what) -> a read-only proxy of t
local function message_class(type_name, name, fields)
  local by_type = message_classes[type_name]
  if not by_type then by_type = {}; message_classes[type_name] = by_type end
  if by_type[name] then return by_type[name] end
  local class = {type_name = type_name, name = name}
  local shown  -- what skills get (below)
  local mmt = {__metatable = false}
  mmt.__index = function(msg, k)
    if type(k) ~= "string" then return nil end
    local f = k:match("^set_(.+)$")
    if f then return function(self, v) values_of[self][f] = v end end
    for _, fname in ipairs(fields) do
      if fname == k then return function(self) return values_of[self][k] end end
    end
    return nil
  end
  -- (msg.field = v, as the messages' plain tables once took it: the value, as set_field(v))
  mmt.__newindex = function(msg, k, v) values_of[msg][k] = v end
  -- Class:new(field values in the definition's order).
  class.new = function(cls, ...)
    if cls ~= shown then fail(2, "%s.%s:new(...): call it with a colon", type_name, name) end
    local msg, values = setmetatable({}, mmt), {}
    for i = 1, select("#", ...) do
      local f = fields[i]
      if not f then fail(2, "%s:new: too many arguments (fields: %s)", name,
                         table.concat(fields, ", ")) end
      values[f] = (select(i, ...))
    end
    message_of[msg], values_of[msg] = class, values
    return msg
  end
  shown = F.readonly and F.readonly(class, type_name .. "." .. name) or class
  by_type[name] = shown
  return shown
end

-- Methods every interface object has.
local common = {}
function common.read(obj) refresh(obj) end
local dirty = {}  -- objects skills wrote since F.written() last looked, in writing order
-- Counts the writes and the messages to interfaces that hold what they are sent (what may change
-- an interface no sensor writes): the agent's blackboard reads such an interface again only when
-- this changed (SkillEngine::blackboard_version).
F.state = {version = 0}
local state = F.state
local function mark_written(obj)
  local m = meta_of[obj]
  state.version = state.version + 1
  m.written = true
  m.written_ns = now_ns()  -- (for the agent's blackboard: when its data last changed)
  if not m.dirty then
    m.dirty = true
    dirty[#dirty + 1] = obj
  end
end
function common.write(obj) mark_written(obj) end
function common.has_writer(obj)
  local m = meta_of[obj]
  return m.write ~= nil or m.written == true
end
function common.is_writer(obj) return meta_of[obj].writing == true end
function common.uid(obj) local m = meta_of[obj]; return m.type .. "::" .. m.id end
function common.id(obj) return meta_of[obj].id end
function common.changed() return true end
local function type_of(obj) return meta_of[obj].type end
function common.msgq_enqueue_copy(obj, msg)
  local m = meta_of[obj]
  local class = message_of[msg]
  if not class or class.type_name ~= m.type then
    fail(2, "%s:msgq_enqueue_copy: expected a message of %s (%s.SomeMessage:new(...))",
         common.uid(obj), m.type, m.var or "iface")
  end
  m.msgid = m.msgid + 1
  epoch = epoch + 1
  local handle = m.t.handle
  local id = handle and handle(data_of[obj], class.name, values_of[msg], m.id, 3) or nil
  if m.store then  -- a message changed the data it holds
    m.written_ns = now_ns()
    state.version = state.version + 1
  end
  return id or m.msgid
end
common.msgq_enqueue = common.msgq_enqueue_copy

local function make_object(type_name, id, t)
  local d = {}
  for f, spec in pairs(t.fields) do d[f] = default_value(spec[1], spec[2]) end
  local w, visible, puck_n = t.writer(id)
  local obj = {}
  meta_of[obj] = {type = type_name, id = id, t = t, write = w ~= "store" and w or nil,
                  visible = visible, puck_n = puck_n, store = w == "store", msgid = 0}
  if w == "store" then meta_of[obj].written = true end
  data_of[obj] = d
  -- llsfsim's own methods answer at every id of its types; before the fields of the same name
  -- at the default id (llsfsim's skills keep their meaning, e.g. light:red() is "OFF" while
  -- nothing is seen), after them elsewhere (a "Light determined" a skill wrote).
  local llsf_obj = t.llsf
  local llsf_first = llsf_obj ~= nil and (id == t.default_id or (t.llsf_first or {})[id])
  local mt = {__metatable = false}
  local lookup
  -- What a key means is fixed per object: looked up once (no closure made per call).
  -- llsfsim's own methods may command the robot: looking one up counts as a command (epoch).
  -- The cache is the object's __index table (a hit costs no call); a miss asks its own __index.
  local cache, commands = {}, {}
  setmetatable(cache, {__index = function(_, k)
    local v = commands[k]
    if v == nil then
      local command
      v, command = lookup(obj, k)
      if v == nil then return nil end
      if not command then
        cache[k] = v
        return v
      end
      commands[k] = v
    end
    epoch = epoch + 1
    return v
  end})
  mt.__index = cache
  lookup = function(_, k)
    local c = common[k]
    if c then return c end
    if llsf_first then
      local v = llsf_obj[k]
      if type(v) == "function" then return v, true end
      if v ~= nil then return v end
    end
    if k == "type" then return type_of end
    if type(k) ~= "string" then return nil end
    local spec = t.fields[k]
    if spec then
      if spec[2] then  -- an array field: iface:name(i), i from 0
        return function(self, i)
          local v = refresh(self)[k]
          if i == nil then  -- the whole array, a copy (the data are shared by the skills)
            local c = {}
            for j = 1, #v do c[j] = v[j] end
            return c
          end
          if type(i) ~= "number" or i < 0 or i >= spec[2] then
            fail(2, "%s:%s(i): index %s out of range 0..%d", common.uid(self), k, tostring(i),
                 spec[2] - 1)
          end
          return v[floor(i) + 1]
        end
      end
      return function(self) return refresh(self)[k] end
    end
    if k:sub(1, 3) == "is_" and t.fields[k:sub(4)] then
      local f = k:sub(4)
      return function(self) return refresh(self)[f] == true end
    end
    local set = k:match("^set_(.+)$")
    if set and t.fields[set] then
      return function(self, a, b)
        local dd = data_of[self]
        if t.fields[set][2] then dd[set][floor(a) + 1] = b else dd[set] = a end
        epoch = epoch + 1
        mark_written(self)  -- (Fawkes' skiller wrote its writing interfaces after every loop)
      end
    end
    local maxlen = k:match("^maxlenof_(.+)$")
    if maxlen and t.fields[maxlen] then
      return function() return t.fields[maxlen][2] or 1 end
    end
    if t.constants and t.constants[k] ~= nil then return t.constants[k] end
    if t.messages[k] then return message_class(type_name, k, t.messages[k]) end
    if llsf_obj then
      local v = llsf_obj[k]
      if type(v) == "function" then return v, true end
      return v
    end
    return nil
  end
  mt.__newindex = function() fail(2, "interfaces are read-only") end
  return setmetatable(obj, mt)
end

-- The interface object of a depends_interfaces entry {v=, type=, id=[, writing=true]}: nil and
-- why for an unknown type or id. Without an id, the type's default (llsfsim's own skills).
local polled = {}  -- objects bound by files written for Fawkes, in binding order
function F.interface(type_name, id, var, writing, poll)
  local t = types[type_name]
  if not t then return llsf[type_name], nil end  -- llsfsim's own types: one per robot, any id
  id = id or t.default_id
  -- Ids llsfsim's own skills gave (names only, before the blackboard) for the default one.
  if t.aliases and t.aliases[id] then id = t.default_id end
  if not id then return nil, fmt("%s needs an id (e.g. id=\"...\")", type_name) end
  if type(id) ~= "string" then return nil, "id must be a string" end
  local uid = type_name .. "::" .. id
  local obj = objects[uid]
  if not obj then
    obj = make_object(type_name, id, t)
    objects[uid] = obj
  end
  local m = meta_of[obj]
  m.var = m.var or var
  if writing then m.writing = true end
  -- (only what has a visibility history: other fields are read when asked for)
  if poll and not m.polled and m.write and t.fields.visibility_history then
    m.polled = true
    polled[#polled + 1] = obj
  end
  return obj
end
-- The interfaces skills wrote (set_field(...) or write()) since the last call, for the agent's
-- blackboard: {type=, id=, serial=, fields={{name, kind, value}, ...}} with kind "symbol",
-- "string", "integer", "float" or "bool" and value a scalar or a list (array fields).
local field_kinds = {string = "string", bool = "bool", int32 = "integer", uint32 = "integer",
                     float = "float", double = "float"}
function F.written()
  local out = {}
  for i = 1, #dirty do
    local obj = dirty[i]
    dirty[i] = nil
    local m = meta_of[obj]
    m.dirty = false
    m.serial = (m.serial or 0) + 1
    local names = {}
    for name in pairs(m.t.fields) do names[#names + 1] = name end
    table.sort(names)
    local fields = {}
    for _, name in ipairs(names) do
      local spec = m.t.fields[name]
      fields[#fields + 1] = {name, field_kinds[spec[1]] or "symbol", data_of[obj][name]}
    end
    out[#out + 1] = {type = m.type, id = m.id, serial = m.serial, fields = fields}
  end
  return out
end

-- The agent's side of the blackboard (docs/fawkes.md, "The blackboard"): a Fawkes-style
-- agent reads, writes and sends messages to the same interface objects as the skills.
local function object_of(type_name, id)
  local t = types[type_name]
  if not t then return nil, fmt("no interface type %s", type_name) end
  if t.aliases and t.aliases[id] then id = t.default_id end
  local uid = type_name .. "::" .. id
  local obj = objects[uid]
  if not obj then
    obj = make_object(type_name, id, t)
    objects[uid] = obj
  end
  return obj
end
local function field_list(obj)
  local m = meta_of[obj]
  local names = m.t.sorted_names  -- (the field names in order, once per type)
  if not names then
    names = {}
    for name in pairs(m.t.fields) do names[#names + 1] = name end
    table.sort(names)
    m.t.sorted_names = names
  end
  local fields = {}
  local enums = m.t.enums or {}
  for _, name in ipairs(names) do
    local v = data_of[obj][name]
    if enums[name] then v = enums[name][v] or v end
    fields[#fields + 1] = {name, field_kinds[m.t.fields[name][1]] or "symbol", v}
  end
  return fields
end
-- {has_writer=, robot=, written_ns=, fields=} of interface (type, id): `robot` if llsfsim's
-- sensors or actuators write it (fresh at every time stamp: written_ns is now), else the time a
-- skill or the agent last wrote it (nil: never); nil and why for an unknown type.
function F.snapshot(type_name, id)
  local obj, why = object_of(type_name, id)
  if not obj then return nil, why end
  local m = meta_of[obj]
  if m.write then refresh(obj) end
  local written_ns = m.write and now_ns() or m.written_ns
  -- (never written: no data to copy; the agent asks again at every cycle)
  return {has_writer = common.has_writer(obj), robot = m.write ~= nil, written_ns = written_ns,
          fields = written_ns and field_list(obj) or {}}
end
-- Writes fields {name = value (a list for an array)} of an interface the agent writes.
function F.set(type_name, id, values)
  local obj, why = object_of(type_name, id)
  if not obj then error(why, 0) end
  local m = meta_of[obj]
  local d = data_of[obj]
  for name, v in pairs(values) do
    local spec = m.t.fields[name]
    if not spec then error(fmt("%s has no field %s", common.uid(obj), name), 0) end
    if spec[2] then
      for i = 1, spec[2] do
        if v[i] ~= nil then d[name][i] = v[i] end
      end
    else
      d[name] = v
    end
  end
  epoch = epoch + 1
  mark_written(obj)
  m.writing = true
end
-- Sends message `name` ("CartesianGotoMessage") with fields {name = value} to the interface's
-- writer, as msgq_enqueue_copy does; returns the message id.
function F.send(type_name, id, name, values)
  local obj, why = object_of(type_name, id)
  if not obj then error(why, 0) end
  local m = meta_of[obj]
  local fields = m.t.messages[name]
  if not fields then
    local names = {}
    for n in pairs(m.t.messages) do names[#names + 1] = n end
    table.sort(names)
    error(fmt("%s has no message %s (it has: %s)", common.uid(obj), name,
              #names > 0 and table.concat(names, ", ") or "none"), 0)
  end
  local class = message_class(type_name, name, fields)
  local msg = class.new(class)
  -- (a field not given is false: the writers take their default for it)
  local given = values_of[msg]
  for _, f in ipairs(fields) do given[f] = false end
  for k, v in pairs(values) do given[k] = v end
  return common.msgq_enqueue_copy(obj, msg)
end

-- Fawkes' skiller read every interface at the start of each loop: the visibility histories of
-- the interfaces files written for Fawkes bound follow the robot from cycle to cycle, read or not.
-- Only the visibility is followed here (a writer's second function; the fields are read when
-- asked for): it is all that a history counts.
function F.poll()
  local now
  local count_ok, count  -- the puck detection's count, read once for every OmniPuck<n>
  for i = 1, #polled do
    local obj = polled[i]
    local m = meta_of[obj]
    local visible = m.visible
    if visible then
      now = now or now_ns()
      local ok, v
      local n = m.puck_n
      if n then  -- (as its visible(): V.count(V) >= n)
        if count_ok == nil then
          local V = llsf.PuckVisionInterface
          count_ok, count = pcall(V.count, V)
        end
        ok = count_ok
        if ok then v = count >= n end
      else
        ok, v = pcall(visible)  -- (a failing read fails at the skill's)
      end
      local d = data_of[obj]
      if ok and d.vis_state ~= v then d.vis_state, d.vis_since = v, now end
    else
      pcall(refresh, obj)
    end
  end
end
function F.type_names()
  local names = {}
  for n in pairs(types) do names[#names + 1] = n end
  for n in pairs(llsf) do if not types[n] then names[#names + 1] = n end end
  table.sort(names)
  return names
end

-- The fawkes table and the modules require knows -------------------------------------------
local noop = function() end
local modinit = {module_init = noop, register_all = noop, register_global_funcs = noop}
F.fawkes = {Time = Time, tf = tf, modinit = modinit, load_yaml_navgraph = load_yaml_navgraph}
F.Time = Time
F.builtin_modules = {["fawkes.modinit"] = modinit, ["fawkes.tf"] = tf}

return F
