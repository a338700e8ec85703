-- SPDX-License-Identifier: MIT
-- The skill DSL runtime (SkillHSM, JumpState, SkillJumpState, skill calls, skill strings).
-- Embedded into llsf_lua at build time and run once per interpreter with the engine's natives;
-- returns the table of entry points the C++ side calls. Skills never see this chunk's globals:
-- each skill module runs in its own environment over the sandboxed `base` table below.
local native = ...

local debug_getinfo = debug.getinfo
local raw_pcall, error, type, tostring, pairs, ipairs = pcall, error, type, tostring, pairs, ipairs
local rawget, rawset, setmetatable, load, select = rawget, rawset, setmetatable, load, select
local fmt, concat = string.format, table.concat
local now_ns, exhausted, log = native.now_ns, native.exhausted, native.log

local S_INACTIVE, S_FINAL, S_RUNNING, S_FAILED = 0, 1, 2, 3
local kMaxStatesPerStep = 32

-- What every skill module and skill string sees (read through __index; never written).
local base = {}
for _, k in ipairs{"assert", "error", "ipairs", "next", "pairs", "rawequal", "rawget", "rawlen",
                   "rawset", "select", "tonumber", "tostring", "type", "getmetatable"} do
  base[k] = _G[k]
end
local function copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = v end
  return c
end

-- Tables every skill of the robot shares (libraries, the DSL's classes, interfaces) are
-- read-only proxies: one skill cannot change what another sees (string.format = ...).
local frozen = setmetatable({}, {__mode = "k"})  -- proxy -> its name
local function readonly(t, what)
  local proxy = setmetatable({}, {
    __index = t,
    __newindex = function(_, k)
      error(fmt("%s is read-only (shared by every skill): cannot set %s.%s", what, what,
                tostring(k)), 2)
    end,
    __pairs = function() return next, t, nil end,
    __len = function() return #t end,
    __metatable = false})
  frozen[proxy] = what
  return proxy
end

-- Library functions whose work grows with their arguments charge it to the instruction budget
-- (native.charge raises at the skill's line); string.rep, find, match, gmatch and gsub are the
-- engine's bounded versions (patterns.cpp). Costs: docs/skills.md, "Sandbox".
local charge = native.charge
local function span(i, j)  -- how many integers i..j (a float: no overflow; "10" counts too)
  i, j = tonumber(i), tonumber(j)
  if not i or not j or j < i then return 0 end
  return (j + 0.0) - i + 1
end
local function len_of(t) return type(t) == "table" and #t or 0 end
local raw_table, raw_string, raw_utf8 = table, string, utf8
local tab = copy(table)
tab.move = function(a1, f, e, t, a2)
  local n = span(f, e)
  charge(n, fmt("table.move of %.0f elements", n))
  return raw_table.move(a1, f, e, t, a2)
end
tab.concat = function(t, sep, i, j)
  local n = span(i or 1, j or len_of(t))
  charge(n, fmt("table.concat of %.0f elements", n))
  return raw_table.concat(t, sep, i, j)
end
tab.unpack = function(t, i, j)
  local n = span(i or 1, j or len_of(t))
  charge(n, fmt("table.unpack of %.0f elements", n))
  return raw_table.unpack(t, i, j)
end
tab.insert = function(t, ...)
  if select("#", ...) >= 2 then
    local n = span((...), len_of(t))
    charge(n, fmt("table.insert moving %.0f elements", n))
  end
  return raw_table.insert(t, ...)
end
tab.remove = function(t, ...)
  if select("#", ...) >= 1 then
    local n = span((...), len_of(t))
    charge(n, fmt("table.remove moving %.0f elements", n))
  end
  return raw_table.remove(t, ...)
end
tab.sort = function(t, comp)
  local n = len_of(t)
  if n > 1 then
    local cost = n * math.ceil(math.log(n, 2))
    charge(cost, fmt("table.sort of %d elements", n))
  end
  return raw_table.sort(t, comp)
end
local str = copy(string)
str.dump = nil
for k, f in pairs(native.patterns) do str[k] = f end
str.byte = function(s, i, j)
  if j ~= nil and type(s) == "string" then charge(#s, fmt("string.byte of %d bytes", #s)) end
  return raw_string.byte(s, i, j)
end
local u8 = copy(utf8)
for _, k in ipairs{"len", "codepoint", "offset"} do
  local f = raw_utf8[k]
  u8[k] = function(s, ...)
    if type(s) == "string" then charge(#s // 8, fmt("utf8.%s of %d bytes", k, #s)) end
    return f(s, ...)
  end
end
base.math = readonly(copy(math), "math")
base.table = readonly(tab, "table")
base.string = readonly(str, "string")
base.utf8 = readonly(u8, "utf8")
base.rawset = function(t, k, v)
  if frozen[t] then error(fmt("%s is read-only (shared by every skill)", frozen[t]), 2) end
  return rawset(t, k, v)
end
-- Method calls on strings ("x"):format(...) use the sandbox's string; the metatable is hidden.
local string_mt = getmetatable("")
string_mt.__index = base.string
string_mt.__metatable = false
base.pcall = native.pcall  -- re-raises once the instruction budget is exhausted
base.setmetatable = function(t, mt)
  -- Finalizers run with hooks off, outside the instruction budget: not allowed.
  if type(mt) == "table" and rawget(mt, "__gc") ~= nil then
    error("__gc metamethods are not allowed in skills", 2)
  end
  return setmetatable(t, mt)
end
base.S_INACTIVE, base.S_FINAL, base.S_RUNNING, base.S_FAILED =
  S_INACTIVE, S_FINAL, S_RUNNING, S_FAILED
base.robot_name = native.robot_name
-- The robot profile (docs/profiles.md): profile.name, profile.stuck_detection; read-only.
base.profile = setmetatable({}, {
  __index = native.profile,
  __newindex = function() error("profile is read-only", 2) end,
  __metatable = false})
frozen[base.profile] = "profile"
-- Fawkes skill files start with `module(..., skillenv.module_init)` and call
-- `skillenv.skill_module(_M)` after their declarations; here declarations are checked as they
-- are assigned, so both are accepted and do nothing.
base.skillenv = readonly({skill_module = function() end, module_init = function() end},
                         "skillenv")
base.module = function() end
base.clock = native.clock
frozen[native.clock] = "clock"

local function args_text(...)
  local n = select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = tostring((select(i, ...))) end
  return concat(parts, "\t")
end
base.print = function(...) log(1, args_text(...)) end
base.print_debug = function(...) log(0, args_text(...)) end
base.print_info = base.print
base.print_warn = function(...) log(2, args_text(...)) end
base.print_error = function(...) log(3, args_text(...)) end
base.printf = function(f, ...) log(1, fmt(f, ...)) end

-- Skill handles (one per skill file, created before any file runs) and the module loading state.
local handles = {}       -- name -> handle
local proxies = {}       -- name -> what skills and skill strings see of the handle (read-only)
local real_of = setmetatable({}, {__mode = "k"})  -- proxy -> handle
local handle_list = {}   -- handles in load order (deterministic iteration)
local loading = nil      -- the handle whose file is running
local interface_types = native.interfaces  -- type name -> interface object (read-only)
for type_name, obj in pairs(interface_types) do frozen[obj] = type_name end
local conventional_vars = {pose = "Position3DInterface", navigator = "NavigatorInterface",
                           motor = "MotorInterface", sensor = "RobotinoSensorInterface",
                           light = "RobotinoLightInterface", pucks = "PuckVisionInterface",
                           laser = "Laser360Interface", puck_detector = "ColourPuckInterface",
                           rescue = "RescueInterface"}

-- The text of an error object: tables and other values would show their address (not the same
-- from one run to the next).
local function error_text(e)
  if type(e) == "string" or type(e) == "number" then return tostring(e) end
  return "(error object is a " .. type(e) .. " value)"
end

local function where(level)
  local info = debug_getinfo(level + 1, "Sl")
  if not info then return "?" end
  return info.short_src .. ":" .. tostring(info.currentline)
end

local function undeclared(h, k)
  if type(k) == "string" then
    if handles[k] then
      return fmt("skill '%s' is used but not declared in depends_skills", k)
    end
    local itype = conventional_vars[k]
    if itype then
      return fmt("interface '%s' is used but not declared in depends_interfaces " ..
                 "(e.g. {v=\"%s\", type=\"%s\"})", k, k, itype)
    end
  end
  return fmt("undeclared global '%s'", tostring(k))
end

-- The environment of one skill module: declarations are checked as they are assigned, reads of
-- unknown names fail with a hint (strict globals).
local function module_env(h)
  local env = {}
  local mt = {__metatable = false}
  mt.__index = function(t, k)
    local v = base[k]
    if v == nil then v = h.bindings[k] end
    if v == nil then error(undeclared(h, k), 2) end
    rawset(t, k, v)
    return v
  end
  mt.__newindex = function(t, k, v)
    if k == "name" then
      if v ~= h.name then
        error(fmt("skill name '%s' does not match its file name '%s.lua'", tostring(v), h.name), 2)
      end
    elseif k == "depends_skills" then
      if v ~= nil and type(v) ~= "table" then error("depends_skills must be a list of names", 2) end
      for i, dep in ipairs(v or {}) do
        if type(dep) ~= "string" then
          error(fmt("depends_skills[%d]: expected a skill name (string)", i), 2)
        end
        if not handles[dep] then error(fmt("depends_skills: unknown skill '%s'", dep), 2) end
        if dep == h.name then error("depends_skills: a skill cannot depend on itself", 2) end
        h.bindings[dep] = proxies[dep]
        h.depends[#h.depends + 1] = dep
      end
    elseif k == "depends_interfaces" then
      if v ~= nil and type(v) ~= "table" then
        error("depends_interfaces must be a list of {v=..., type=...}", 2)
      end
      for i, d in ipairs(v or {}) do
        if type(d) ~= "table" or type(d.v) ~= "string" or type(d.type) ~= "string" then
          error(fmt("depends_interfaces[%d]: expected {v=\"name\", type=\"Type\"[, id=\"Id\"]}", i), 2)
        end
        local obj = interface_types[d.type]
        if not obj then
          error(fmt("depends_interfaces[%d]: unknown interface type '%s' (known: %s)", i, d.type,
                    native.interface_names), 2)
        end
        h.bindings[d.v] = obj
      end
    end
    rawset(t, k, v)
  end
  env._M = env
  return setmetatable(env, mt)
end

-- States -------------------------------------------------------------------------------------
local JumpState = readonly({kind = "jump"}, "JumpState")
local SkillJumpState = readonly({kind = "skill"}, "SkillJumpState")
base.JumpState, base.SkillJumpState = JumpState, SkillJumpState

local SkillHSM = {}
SkillHSM.__index = SkillHSM
SkillHSM.__metatable = false  -- getmetatable(fsm) must not hand out the shared class
local fsms = setmetatable({}, {__mode = "k"})  -- every SkillHSM made by SkillHSM:new
base.SkillHSM = readonly(SkillHSM, "SkillHSM")

local function new_state(fsm, name, kind)
  local st = {name = name, fsm = fsm, kind = kind, transitions = {}, preconds = {}, args = {},
              entered_ns = 0, visit = 0}
  fsm.states[name] = st
  fsm.state_list[#fsm.state_list + 1] = st
  return st
end

function SkillHSM:new(o)
  if type(o) ~= "table" or type(o.start) ~= "string" then
    error("SkillHSM:new{name=..., start=\"STATE\"}: 'start' must name a state", 2)
  end
  if not loading then error("SkillHSM:new can only be called while a skill file loads", 2) end
  local fsm = setmetatable({name = o.name or loading.name, start = o.start, debug = o.debug,
                            states = {}, state_list = {}, defaults = {}, vars = {},
                            closure = {}, skill = loading, where = where(2), step_id = 0},
                           SkillHSM)
  fsms[fsm] = true
  fsm.cond_env = setmetatable(fsm.closure, {__index = loading.env})
  fsm.final = new_state(fsm, "FINAL", "final")
  fsm.failed = new_state(fsm, "FAILED", "failed")
  return fsm
end

local function resolve_subskill(fsm, spec, lvl)
  local s = spec[1]
  local h = type(s) == "string" and handles[s] or real_of[s]
  if not h then error(fmt("skills: entry %s is not a skill", tostring(s)), lvl) end
  if fsm.skill.bindings[h.name] ~= proxies[h.name] then
    error(fmt("skill '%s' is used but not declared in depends_skills", h.name), lvl)
  end
  local static = nil
  for k, v in pairs(spec) do
    if k ~= 1 then static = static or {}; static[k] = v end
  end
  return {handle = h, static = static}
end

function SkillHSM:define_states(spec)
  local export = spec.export_to or self.skill.env
  for k, v in pairs(spec.closure or {}) do self.closure[k] = v end
  local pending = {}
  for _, e in ipairs(spec) do
    local name, class = e[1], e[2] or JumpState
    if type(name) ~= "string" then error("define_states: a state needs a name", 2) end
    if self.states[name] then error(fmt("define_states: state '%s' is defined twice", name), 2) end
    if class ~= JumpState and class ~= SkillJumpState then
      error(fmt("define_states: state '%s': class must be JumpState or SkillJumpState", name), 2)
    end
    local st = new_state(self, name, class.kind)
    if class == SkillJumpState then
      if type(e.skills) ~= "table" or #e.skills == 0 then
        error(fmt("SkillJumpState '%s' needs skills={{skill}, ...}", name), 2)
      end
      st.skills = {}
      for i, s in ipairs(e.skills) do
        st.skills[i] = resolve_subskill(self, type(s) == "table" and not s.is_skill and s or {s}, 3)
      end
      st.final_to, st.fail_to = e.final_to, e.fail_to or "FAILED"
      if type(st.final_to) ~= "string" then
        error(fmt("SkillJumpState '%s' needs final_to=\"STATE\"", name), 2)
      end
    end
    if e.timeout ~= nil then pending[#pending + 1] = {st, e.timeout} end
    rawset(export, name, st)
  end
  for _, st in ipairs(self.state_list) do
    for _, f in ipairs{"final_to", "fail_to"} do
      if st[f] and not self.states[st[f]] then
        error(fmt("state '%s': %s names unknown state '%s'", st.name, f, st[f]), 2)
      end
    end
  end
  -- State timeouts: timeout={secs, "TO", error="..."}.
  for _, p in ipairs(pending) do
    local st, t = p[1], p[2]
    local secs, to = t, "FAILED"
    if type(t) == "table" then secs, to = t[1], t[2] or "FAILED" end
    if type(secs) ~= "number" or not self.states[to] then
      error(fmt("state '%s': timeout must be secs or {secs, \"STATE\"}", st.name), 2)
    end
    self:add_transitions{{st.name, to, timeout = secs,
                          error = type(t) == "table" and t.error or nil}}
  end
end

local function compile_cond(fsm, c, what, loc, lvl)
  if c == true then return true end
  if type(c) == "function" then return c end
  if type(c) ~= "string" then error(fmt("%s must be a function, a string or true", what), lvl) end
  local f, err = load("local self, vars, fsm = ...; return (" .. c .. ")",
                      "=" .. loc .. " " .. what, "t", fsm.cond_env)
  if not f then error(fmt("bad %s \"%s\": %s", what, c, err), lvl) end
  return f
end

function SkillHSM:add_transitions(spec)
  local loc = where(2)
  for i, t in ipairs(spec) do
    if type(t) ~= "table" or type(t[1]) ~= "string" then
      error(fmt("add_transitions: entry %d must be {\"FROM\", \"TO\", cond=...}", i), 2)
    end
    local from, to = t[1], t[2]
    if to == nil then from, to = nil, t[1] end
    if from and not self.states[from] then
      error(fmt("add_transitions: unknown state '%s'", from), 2)
    end
    if not self.states[to] then error(fmt("add_transitions: unknown state '%s'", to), 2) end
    local tr = {from = from, to = self.states[to], desc = t.desc, error = t.error, where = loc}
    if t.cond ~= nil then tr.cond = compile_cond(self, t.cond, "cond", loc, 3) end
    if t.precond ~= nil then tr.precond = compile_cond(self, t.precond, "precond", loc, 3) end
    if t.cond_and_precond ~= nil then
      tr.cond = compile_cond(self, t.cond_and_precond, "cond", loc, 3)
      tr.precond = tr.cond
    end
    if t.timeout ~= nil then
      local secs = t.timeout
      if type(secs) == "table" then tr.error = tr.error or secs.error; secs = secs[1] end
      if type(secs) ~= "number" or secs < 0 then
        error("add_transitions: timeout must be a number of seconds >= 0", 2)
      end
      tr.timeout_ns = math.floor(secs * 1e9 + 0.5)
      tr.label = fmt("timeout after %g s", secs)
    end
    if not tr.cond and not tr.precond and not tr.timeout_ns then
      error(fmt("add_transitions: transition to '%s' needs cond, precond or timeout", to), 2)
    end
    local text = t.cond or t.cond_and_precond or t.precond
    tr.label = tr.label or tr.desc or (type(text) == "string" and text) or "condition"
    if from then
      local st = self.states[from]
      if tr.cond or tr.timeout_ns then st.transitions[#st.transitions + 1] = tr end
      if tr.precond then st.preconds[#st.preconds + 1] = tr end
    else
      self.defaults[#self.defaults + 1] = tr
    end
  end
end

-- Skill calls --------------------------------------------------------------------------------
local call_skill, reset_skill

local function holds(c, st, fsm)
  if c == true then return true end
  return c(st, fsm.vars, fsm)
end

local function check(tr, st, fsm, now)
  if tr.timeout_ns and now - st.entered_ns >= tr.timeout_ns then return true end
  return tr.cond ~= nil and holds(tr.cond, st, fsm) and true or false
end

-- Sub-skills of a SkillJumpState: next state and error text once they are done.
local function run_subskills(fsm, st)
  local all_final = true
  for _, sk in ipairs(st.skills) do
    local h = sk.handle
    local status = call_skill(h, st.args[h.name] or sk.static or fsm.vars)
    if status == S_FAILED then
      return fsm.states[st.fail_to], fmt("%s()/%s failed: %s", st.name, h.name,
                                          tostring(h.error))
    elseif status ~= S_FINAL then
      all_final = false
    end
  end
  if all_final then return fsm.states[st.final_to], nil end
  return nil, nil
end

-- Enters `st` (following preconditions) and returns the state actually entered.
local function enter(fsm, st, now)
  for _ = 1, kMaxStatesPerStep do
    local jumped = false
    for _, tr in ipairs(st.preconds) do
      fsm.running = st
      if holds(tr.precond, st, fsm) then
        if tr.to == fsm.failed and not fsm.error then
          fsm.error = tr.error or fmt("%s: precondition %s", st.name, tr.label)
        end
        if fsm.debug then log(0, fmt("%s: %s -> %s (precond)", fsm.name, st.name, tr.to.name)) end
        st = tr.to
        jumped = true
        break
      end
    end
    if not jumped then break end
  end
  st.entered_ns = now
  st.args = {}
  st.error = nil
  fsm.current = st
  fsm.running = st
  if st.skills then
    for _, sk in ipairs(st.skills) do reset_skill(sk.handle) end
  end
  if st.init then st:init() end
  return st
end

local function leave(fsm, st, to, tr, err)
  if st.exit then fsm.running = st; st:exit() end
  local e = err or (tr and tr.error)
  if to == fsm.failed and not fsm.error then
    fsm.error = e or fmt("%s: %s", st.name, tr and tr.label or "failed")
  elseif e then
    st.error = e
  end
  if fsm.debug then
    log(0, fmt("%s: %s -> %s (%s)", fsm.name, st.name, to.name, tr and tr.label or "skills"))
  end
end

-- One FSM step: loop hook, sub-skills and transitions of the current state; a state entered in
-- this step runs in the same step unless it already ran in it.
local function fsm_step(fsm)
  local now = now_ns()
  fsm.step_id = fsm.step_id + 1
  local st = fsm.current or enter(fsm, fsm.states[fsm.start], now)
  for _ = 1, kMaxStatesPerStep do
    if st.kind == "final" or st.kind == "failed" or st.visit == fsm.step_id then break end
    st.visit = fsm.step_id
    fsm.running = st
    if st.loop then st:loop() end
    local to, tr, err = nil, nil, nil
    if fsm.error == nil then
      if st.skills then to, err = run_subskills(fsm, st) end
      if not to then
        for _, t in ipairs(st.transitions) do
          if check(t, st, fsm, now) then to, tr = t.to, t; break end
        end
      end
      if not to then
        for _, t in ipairs(fsm.defaults) do
          if check(t, st, fsm, now) then to, tr = t.to, t; break end
        end
      end
    else
      to = fsm.failed  -- the skill set fsm.error: failure
    end
    if not to then break end
    leave(fsm, st, to, tr, err)
    st = enter(fsm, to, now)
  end
  if st.kind == "final" then return S_FINAL end
  if st.kind == "failed" then
    fsm.error = fsm.error or "FAILED"
    return S_FAILED
  end
  if fsm.error ~= nil then
    leave(fsm, st, fsm.failed, nil, nil)
    enter(fsm, fsm.failed, now)
    return S_FAILED
  end
  return S_RUNNING
end

local function step(h)
  if h.fsm then return fsm_step(h.fsm), h.fsm.error end
  local s, err = h.env.execute(h.vars)
  if s ~= S_RUNNING and s ~= S_FINAL and s ~= S_FAILED then
    error(fmt("execute() returned %s, expected S_RUNNING, S_FINAL or S_FAILED", tostring(s)))
  end
  return s, err
end

local depth = 0
local caller = nil     -- the handle whose step is running
local cycle_id = 0
local called = {}      -- handles called by the skill string in this cycle
local active = {}      -- handles started since the last reset_all

reset_skill = function(h)
  if h.active then
    local fsm = h.fsm
    if fsm and fsm.current and fsm.current.exit and fsm.current.kind ~= "final" and
       fsm.current.kind ~= "failed" then
      local ok, err = raw_pcall(fsm.current.exit, fsm.current)
      if not ok then log(3, fmt("%s: exit of %s: %s", h.name, fsm.current.name, error_text(err))) end
    end
    if not h.fsm and rawget(h.env, "reset") then
      local ok, err = raw_pcall(h.env.reset)
      if not ok then log(3, fmt("%s: reset(): %s", h.name, error_text(err))) end
    end
  end
  if h.fsm then
    h.fsm.current, h.fsm.error, h.fsm.result, h.fsm.vars = nil, nil, nil, {}
    for _, st in ipairs(h.fsm.state_list) do st.visit = 0 end
  end
  h.active, h.status, h.error, h.vars = false, S_INACTIVE, nil, nil
  for i = #h.children, 1, -1 do
    local c = h.children[i]
    h.children[i] = nil
    c.child_of = nil
    reset_skill(c)
  end
end

call_skill = function(h, args)
  if h.load_error then
    error(fmt("skill '%s' is not available: %s", h.name, h.load_error), 0)
  end
  if h.in_call then error(fmt("recursive call of skill '%s'", h.name), 0) end
  if args ~= nil and type(args) ~= "table" then
    error(fmt("skill '%s': arguments must be a table, e.g. %s{key=value}", h.name, h.name), 0)
  end
  if not h.active then
    local vars = {}
    for k, v in pairs(args or {}) do vars[k] = v end
    h.active, h.status, h.error = true, S_RUNNING, nil
    if h.fsm then h.fsm.vars = vars else h.vars = vars end
    active[#active + 1] = h
  elseif h.status ~= S_RUNNING then
    return h.status
  end
  if caller and h.child_of ~= caller then
    caller.children[#caller.children + 1] = h
    h.child_of = caller
  end
  local outer = caller
  caller, h.in_call, depth = h, true, depth + 1
  local ok, status, err = raw_pcall(step, h)
  caller, h.in_call, depth = outer, false, depth - 1
  if ok then
    h.status = status
    if status == S_FAILED then h.error = err == nil and "failed" or error_text(err) end
    return status
  end
  local running = h.fsm and h.fsm.running
  h.status = S_FAILED
  h.error = running and (running.name .. ": " .. error_text(status)) or error_text(status)
  if h.fsm then
    h.fsm.error = h.error
    h.fsm.current = h.fsm.failed
  end
  if exhausted() then error(h.name .. ": " .. h.error, 0) end
  return S_FAILED
end

local handle_mt = {__metatable = false}
handle_mt.__index = {
  reset = function(h) reset_skill(h) end,
}
handle_mt.__call = function(h, args)
  if depth == 0 and h.called ~= cycle_id then
    h.called = cycle_id
    called[#called + 1] = h
  end
  return call_skill(h, args)
end

-- Skills see a read-only proxy of each handle: they can call it, reset it and read its name,
-- status and error, but not reach or change another skill's state machine or environment.
local visible = {name = true, is_skill = true, status = true, error = true, documentation = true}
local proxy_mt = {__metatable = false}
proxy_mt.__index = function(p, k)
  local h = real_of[p]
  if k == "reset" then return function() reset_skill(h) end end
  if visible[k] then return h[k] end
  return nil
end
proxy_mt.__newindex = function(p, k)
  local name = real_of[p].name
  error(fmt("skill '%s' is read-only: cannot set %s.%s", name, name, tostring(k)), 2)
end
proxy_mt.__call = function(p, args) return handle_mt.__call(real_of[p], args) end
proxy_mt.__tostring = function(p) return "skill " .. real_of[p].name end

-- Entry points for the C++ engine ------------------------------------------------------------
local E = {}

function E.declare_skills(names)
  for _, name in ipairs(names) do
    local h = setmetatable({name = name, is_skill = true, bindings = {}, depends = {},
                            children = {}, active = false, status = S_INACTIVE, called = 0},
                           handle_mt)
    handles[name] = h
    handle_list[#handle_list + 1] = h
    local p = setmetatable({}, proxy_mt)
    real_of[p] = h
    proxies[name] = p
    frozen[p] = "skill " .. name
  end
end

function E.begin_module(name, path)
  local h = handles[name]
  h.path = path
  h.env = module_env(h)
  loading = h
  return h.env
end

-- Checks a loaded module's declarations; errors name the file (and line where one is known).
function E.finish_module(name)
  local h = handles[name]
  loading = nil
  local env = h.env
  local function fail(msg) error(h.path .. ": " .. msg, 0) end
  if rawget(env, "name") == nil then fail("the skill declares no 'name'") end
  if type(rawget(env, "documentation")) ~= "string" then
    fail("the skill declares no 'documentation' string")
  end
  local fsm = rawget(env, "fsm")
  if fsm ~= nil then
    if not fsms[fsm] then fail("'fsm' must be a SkillHSM") end
    if not fsm.states[fsm.start] then
      error(fmt("%s: start state '%s' is not defined", fsm.where, fsm.start), 0)
    end
    h.fsm = fsm
  elseif type(rawget(env, "execute")) ~= "function" then
    fail("the skill has neither an 'fsm' nor an execute() function")
  end
  h.documentation = env.documentation
end

function E.set_load_error(name, msg)
  loading = nil
  handles[name].load_error = msg
end

-- Marks skills whose dependencies failed to load (to a fixpoint).
function E.resolve()
  local changed = true
  while changed do
    changed = false
    for _, h in ipairs(handle_list) do
      if not h.load_error then
        for _, dep in ipairs(h.depends) do
          if handles[dep].load_error then
            h.load_error = fmt("depends on skill '%s', which failed to load", dep)
            changed = true
            break
          end
        end
      end
    end
  end
end

function E.skill_info(name)
  local h = handles[name]
  if not h then return nil end
  local state = h.fsm and h.fsm.current and h.fsm.current.name or ""
  return h.status, h.error or "", state, h.load_error or "", h.path or "",
         h.documentation or "", concat(h.depends, ",")
end

local string_env = setmetatable({}, {
  __index = function(t, k)
    local v = proxies[k] or base[k]
    if v == nil then error(fmt("unknown skill '%s'", tostring(k)), 2) end
    rawset(t, k, v)
    return v
  end,
  __metatable = false})

function E.compile(s)
  return load(s, "=skill string", "t", string_env)
end

function E.run_cycle(chunk)
  cycle_id = cycle_id + 1
  for i = #called, 1, -1 do called[i] = nil end
  depth, caller = 0, nil
  chunk()
  local status, errors, results = S_FINAL, nil, nil
  for _, h in ipairs(called) do
    local r = h.fsm and h.fsm.result
    if r ~= nil and h.status ~= S_RUNNING then
      results = results or {}
      results[#results + 1] = tostring(r)
    end
    if h.status == S_FAILED then
      status = S_FAILED
      errors = errors or {}
      errors[#errors + 1] = h.name .. ": " .. tostring(h.error)
    elseif h.status == S_RUNNING and status ~= S_FAILED then
      status = S_RUNNING
    end
  end
  return status, errors and concat(errors, "; ") or nil, results and concat(results, "; ") or ""
end

function E.reset_all()
  depth, caller = 0, nil
  for i = #active, 1, -1 do
    local h = active[i]
    active[i] = nil
    if not h.child_of then reset_skill(h) end
  end
end

return E
