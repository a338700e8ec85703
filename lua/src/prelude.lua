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
-- Entry points for the C++ engine (filled below). E.raised_reason: the reason code of the error
-- last raised on purpose (an unknown skill), read by the engine when a string's run fails with
-- an error (lua::FailReason; docs/skills.md, "Failure reasons").
local E = {}
-- The reasons fsm.reason may hold: those a skill declares ("aborted", "not-found") and those it
-- hands on from a sub-skill (fail_to, or self.fsm.reason = self.fsm.states.X.reason).
local kDeclaredReasons = {["aborted"] = true, ["not-found"] = true, ["failed"] = true,
                          ["unknown-skill"] = true, ["error"] = true, ["budget"] = true}
-- The engine's links from a skill's own tables to real handles, kept out of those tables: a
-- skill gets its state machine as `fsm` and its states as `self`, and could otherwise walk from
-- them to its own handle and on (children, child_of) to any other skill's state machine.
local fsms = setmetatable({}, {__mode = "k"})  -- every SkillHSM made by SkillHSM:new -> its skill
local subskills_of = setmetatable({}, {__mode = "k"})  -- a SkillJumpState -> its sub-skills
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
    __call = function(_, ...) return t(...) end,  -- a callable class (fawkes.tf.StampedPose)
    __metatable = false})
  frozen[proxy] = what
  return proxy
end

-- Library functions whose work grows with their arguments charge it to the instruction budget
-- (native.charge raises at the skill's line); string.rep, find, match, gmatch and gsub are the
-- engine's bounded versions (patterns.cpp). Costs: docs/skills.md, "Sandbox".
local charge = native.charge
local prelude_src = debug_getinfo(1, "S").short_src
-- Errors of the library functions the prelude wraps name the skill's line, not the wrapper's
-- (Lua would say "llsf/prelude.lua:NN: bad argument ..."): `f` runs protected, and an error
-- without a position is raised again at the nearest caller outside the prelude. Errors that
-- carry one (a comparator's, a budget's) and non-string errors pass unchanged.
local function raise_at_skill(e)
  if type(e) ~= "string" or e:find("^[^\n]-:%d+: ") then error(e, 0) end
  for level = 2, 50 do
    local info = debug_getinfo(level, "Sl")
    if not info then break end
    if info.short_src ~= prelude_src and info.currentline > 0 then
      error(info.short_src .. ":" .. info.currentline .. ": " .. e, 0)
    end
  end
  error(e, 0)
end
local function relayed(ok, ...)
  if ok then return ... end
  raise_at_skill((...))
end
local function relay(f, ...) return relayed(raw_pcall(f, ...)) end
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
  return relay(raw_table.move, a1, f, e, t, a2)
end
tab.concat = function(t, sep, i, j)
  local n = span(i or 1, j or len_of(t))
  charge(n, fmt("table.concat of %.0f elements", n))
  return relay(raw_table.concat, t, sep, i, j)
end
tab.unpack = function(t, i, j)
  local n = span(i or 1, j or len_of(t))
  charge(n, fmt("table.unpack of %.0f elements", n))
  return relay(raw_table.unpack, t, i, j)
end
tab.insert = function(t, ...)
  if select("#", ...) >= 2 then
    local n = span((...), len_of(t))
    charge(n, fmt("table.insert moving %.0f elements", n))
  end
  return relay(raw_table.insert, t, ...)
end
tab.remove = function(t, ...)
  if select("#", ...) >= 1 then
    local n = span((...), len_of(t))
    charge(n, fmt("table.remove moving %.0f elements", n))
  end
  return relay(raw_table.remove, t, ...)
end
tab.sort = function(t, comp)
  local n = len_of(t)
  if n > 1 then
    local cost = n * math.ceil(math.log(n, 2))
    charge(cost, fmt("table.sort of %d elements", n))
  end
  return relay(raw_table.sort, t, comp)
end
local str = copy(string)
str.dump = nil
for k, f in pairs(native.patterns) do str[k] = f end
str.byte = function(s, i, j)
  if j ~= nil and type(s) == "string" then charge(#s, fmt("string.byte of %d bytes", #s)) end
  return relay(raw_string.byte, s, i, j)
end
local u8 = copy(utf8)
for _, k in ipairs{"len", "codepoint", "offset"} do
  local f = raw_utf8[k]
  u8[k] = function(s, ...)
    if type(s) == "string" then charge(#s // 8, fmt("utf8.%s of %d bytes", k, #s)) end
    return relay(f, s, ...)
  end
end
base.math = readonly(copy(math), "math")
base.table = readonly(tab, "table")
base.string = readonly(str, "string")
base.utf8 = readonly(u8, "utf8")
base.rawset = function(t, k, v)
  if frozen[t] then error(fmt("%s is read-only (shared by every skill)", frozen[t]), 2) end
  return relay(rawset, t, k, v)
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
  return relay(setmetatable, t, mt)
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
-- are assigned, so both are accepted and do nothing (a file already is its own module).
local noop = function() end
base.skillenv = readonly({skill_module = noop, module_init = noop, use_skill = noop}, "skillenv")
local loading  -- the handle whose file is running (set by E.begin_module)
-- module(...) marks a file written for Fawkes (see define_states: state timeouts).
base.module = function() if loading then loading.fawkes_style = true end end
-- What skills written for Fawkes find besides (fawkes.lua): fawkes.Time, fawkes.tf, fawkes.modinit,
-- fawkes.load_yaml_navgraph, the tf transformer, the config, require's built-in modules.
local fawkes = native.fawkes
fawkes.readonly = readonly  -- for the message classes it makes on demand
local fawkes_tf
do
  local tf_classes = {}
  for k, v in pairs(fawkes.fawkes.tf) do
    tf_classes[k] = type(v) == "table" and readonly(v, "fawkes.tf." .. k) or v
  end
  fawkes_tf = readonly(tf_classes, "fawkes.tf")
end
local fawkes_modinit = readonly(fawkes.fawkes.modinit, "fawkes.modinit")
base.Time = readonly(fawkes.Time, "fawkes.Time")
base.fawkes = readonly({Time = base.Time, tf = fawkes_tf, modinit = fawkes_modinit,
                        load_yaml_navgraph = fawkes.fawkes.load_yaml_navgraph}, "fawkes")
base.tf = readonly(fawkes.tf_transformer, "tf")
base.config = readonly(fawkes.config, "config")
local builtin_modules = {["fawkes.modinit"] = fawkes_modinit, ["fawkes.tf"] = fawkes_tf}
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
base.printf = function(f, ...)
  local ok, text = raw_pcall(fmt, f, ...)
  if not ok then
    text = tostring(text):gsub("to '[%w.]*format'", "to 'printf'")
    raise_at_skill(text)
  end
  log(1, text)
end

-- Skill handles (one per skill file, created before any file runs) and the module loading state.
local handles = {}       -- name -> handle
local proxies = {}       -- name -> what skills and skill strings see of the handle (read-only)
local real_of = setmetatable({}, {__mode = "k"})  -- proxy -> handle
local handle_list = {}   -- handles in load order (deterministic iteration)
loading = nil            -- the handle whose file is running
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

-- "Did you mean" ------------------------------------------------------------------------------
-- Edit distance (insert, delete, substitute, swap two neighbours), ignoring case.
local function distance(a, b)
  a, b = a:lower(), b:lower()
  local la, lb = #a, #b
  if math.abs(la - lb) > 3 then return 99 end
  local d = {}
  for i = 0, la do d[i] = {[0] = i} end
  for j = 0, lb do d[0][j] = j end
  for i = 1, la do
    for j = 1, lb do
      local cost = a:byte(i) == b:byte(j) and 0 or 1
      local v = math.min(d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost)
      if i > 1 and j > 1 and a:byte(i) == b:byte(j - 1) and a:byte(i - 1) == b:byte(j) then
        v = math.min(v, d[i - 2][j - 2] + 1)
      end
      d[i][j] = v
    end
  end
  return d[la][lb]
end

-- The candidate (a list of names) nearest to `name` if it is near enough to be a typo: at most
-- 1 edit for names of 3 or 4 characters, 2 up to 8, else 3 (names of 1 or 2 characters: only
-- another case); ties go to the first in name order.
local function nearest(name, candidates)
  if type(name) ~= "string" or #name > 64 then return nil end
  local limit = #name <= 2 and 0 or #name <= 4 and 1 or #name <= 8 and 2 or 3
  local best, best_d = nil, limit + 1
  local names = {}
  for _, c in ipairs(candidates) do
    if type(c) == "string" and c ~= name and #c <= 64 then names[#names + 1] = c end
  end
  table.sort(names)
  for _, c in ipairs(names) do
    do
      local d = distance(name, c)
      if d < best_d then best, best_d = c, d end
    end
  end
  return best
end

local function did_you_mean(name, candidates)
  local n = nearest(name, candidates)
  return n and fmt(" (did you mean '%s'?)", n) or ""
end

local function state_names(fsm)  -- the skill's own states first, then FINAL and FAILED
  local names = {}
  for i = 3, #fsm.state_list do names[#names + 1] = fsm.state_list[i].name end
  names[#names + 1] = "FINAL"
  names[#names + 1] = "FAILED"
  return names
end

-- "unknown state 'DRVE' (did you mean 'DRIVE'? states: START, DRIVE, FINAL, FAILED)"
local function unknown_state(fsm, name)
  local names = state_names(fsm)
  local near = nearest(name, state_names(fsm))
  return fmt("unknown state '%s' (%sstates: %s)", tostring(name),
             near and fmt("did you mean '%s'? ", near) or "", concat(names, ", "))
end

-- Globals skills do not have, with what to use instead.
local unavailable = {
  os = "no files, processes or wall clock: for time use clock.now() (game seconds) " ..
       "or a transition's timeout=SECS",
  io = "no files or terminal: print(...) / printf(fmt, ...) write to the log",
  package = "skills load no modules: name another skill in depends_skills = {\"skill\"}",
  dofile = "skills load no other files: name another skill in depends_skills = {\"skill\"}",
  loadfile = "skills load no other files: name another skill in depends_skills = {\"skill\"}",
  load = "skills compile no code at run time: write a function instead (a cond may be a " ..
         "function or a string the engine compiles at load time)",
  loadstring = "skills compile no code at run time (and loadstring is Lua 5.1's): write a " ..
               "function instead",
  debug = "print(...) what you want to see",
  coroutine = "wait in a state with a transition (cond=..., timeout=...)",
  collectgarbage = "the engine manages memory: drop references (t = nil) instead",
  _G = "a skill's own globals are in _M",
  unpack = "it is Lua 5.1's: use table.unpack",
  setfenv = "it is Lua 5.1's (a skill's globals are in _M)",
  getfenv = "it is Lua 5.1's (a skill's globals are in _M)",
}

-- "file:line" of the code `level` levels up (1: the caller of where()'s caller), or of the
-- nearest skill code above it if that is the prelude's own (define_states adds a state's timeout
-- through add_transitions).
local function where(level)
  local l = level + 1
  local info = debug_getinfo(l, "Sl")
  while info and info.short_src == prelude_src do
    l = l + 1
    info = debug_getinfo(l, "Sl")
  end
  if not info then return "?" end
  return info.short_src .. ":" .. tostring(info.currentline)
end

local function undeclared(h, k, env)
  if type(k) == "string" then
    if unavailable[k] then
      return fmt("'%s' is not available in skills: %s", k, unavailable[k])
    end
    if handles[k] then
      return fmt("skill '%s' is used but not declared in depends_skills", k)
    end
    local itype = conventional_vars[k]
    if itype then
      return fmt("interface '%s' is used but not declared in depends_interfaces " ..
                 "(e.g. {v=\"%s\", type=\"%s\"})", k, k, itype)
    end
  end
  if k == "fsm" then
    return "undeclared global 'fsm': create the state machine first: " ..
           "fsm = SkillHSM:new{name=name, start=\"STATE\"}"
  end
  local candidates = {}
  if env then
    for name in next, env do candidates[#candidates + 1] = name end
  end
  for name in pairs(base) do candidates[#candidates + 1] = name end
  for name in pairs(h.bindings) do candidates[#candidates + 1] = name end
  for name in pairs(conventional_vars) do candidates[#candidates + 1] = name end
  for name in pairs(handles) do candidates[#candidates + 1] = name end
  local meant = did_you_mean(k, candidates)
  -- An upper-case name before fsm:define_states{...} made any state (states are globals it
  -- exports) may be a state used too early, or a constant or typo: say both.
  local fsm = env and rawget(env, "fsm")
  if type(k) == "string" and meant == "" and fsms[fsm] and #fsm.state_list <= 2 and
     k:find("^[%u_][%u%d_]*$") then
    return fmt("undeclared global '%s': if it is a state, no state is defined yet: call " ..
               "fsm:define_states{...} before using it (function %s:init() ...); otherwise " ..
               "define it before this line (local %s = ...)", k, k, k)
  end
  return fmt("undeclared global '%s'%s", tostring(k), meant)
end

-- The environment of one skill module: declarations are checked as they are assigned, reads of
-- unknown names fail with a hint (strict globals).
local function module_env(h)
  local env = {}
  local mt = {__metatable = false}
  mt.__index = function(t, k)
    local v = base[k]
    if v == nil then v = h.bindings[k] end
    if v == nil then
      -- A file written for Fawkes (module(...)) reads unknown globals as nil, as Fawkes'
      -- modules did (the team's closures name functions that do not exist): a warning, once.
      if h.fawkes_style then
        h.nil_globals = h.nil_globals or {}
        if not h.nil_globals[k] then
          h.nil_globals[k] = true
          log(2, fmt("%s: %s (nil: a file written for Fawkes reads unknown globals as nil)",
                     where(2), undeclared(h, k, t)))
        end
        return nil
      end
      error(undeclared(h, k, t), 2)
    end
    rawset(t, k, v)
    return v
  end
  mt.__newindex = function(t, k, v)
    if k == "name" then
      h.name_where = where(2)
      if v ~= h.name then
        error(fmt("skill name '%s' does not match its file name '%s.lua'", tostring(v), h.name), 2)
      end
    elseif k == "depends_skills" then
      if v ~= nil and type(v) ~= "table" then error("depends_skills must be a list of names", 2) end
      for i, dep in ipairs(v or {}) do
        if type(dep) ~= "string" then
          error(fmt("depends_skills[%d]: expected a skill name (string)", i), 2)
        end
        if not handles[dep] then
          h.load_reason = "unknown-skill"
          error(fmt("depends_skills: unknown skill '%s'", dep), 2)
        end
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
        -- Fawkes' types (fawkes.lua) by id, with llsfsim's methods at the default id.
        local obj, why = fawkes.interface(d.type, d.id, d.v, d.writing, h.fawkes_style)
        if not obj then
          error(fmt("depends_interfaces[%d]: %s", i, why or
                    fmt("unknown interface type '%s' (known: %s)", d.type,
                        concat(fawkes.type_names(), ", "))), 2)
        end
        if not frozen[obj] then frozen[obj] = d.type end
        h.bindings[d.v] = obj
      end
    end
    rawset(t, k, v)
  end
  env._M = env
  return setmetatable(env, mt)
end

-- require: helper modules ---------------------------------------------------------------------
-- Fawkes' skills share code through Lua modules (a team's tf_module.lua, machine_pos_module.lua):
-- require("name") loads name.lua ("a.b": a/b.lua) of the module directories or else of the skill
-- directories, once per interpreter, read-only, in an environment of its own over the skills'
-- globals; it returns what the file returns, else its globals (its _M, as Fawkes' module()).
local modules = {}    -- name -> the module
local requiring = {}  -- names being loaded (a cycle is an error)

-- Unknown globals read as nil (as in Fawkes' modules), with a warning once per name.
local function helper_env(name)
  local env, warned = {}, {}
  env._M = env
  return setmetatable(env, {__metatable = false, __index = function(_, k)
    local v = base[k]
    if v == nil and not warned[k] then
      warned[k] = true
      local candidates = {}
      for n in pairs(base) do candidates[#candidates + 1] = n end
      log(2, fmt("%s: undeclared global '%s' (in module '%s')%s is nil", where(2), tostring(k),
                 name, did_you_mean(k, candidates)))
    end
    return v
  end})
end

base.require = function(name)
  if type(name) ~= "string" then error("require: expected a module name (a string)", 2) end
  local m = modules[name] or builtin_modules[name]
  if m ~= nil then return m end
  if requiring[name] then error(fmt("require: module '%s' requires itself (a cycle)", name), 2) end
  local text, path, in_skill_dir = native.read_module(name)
  -- The file of a skill of the skill directories (a module directory did not have the name).
  local h = handles[name]
  local own = h and not h.is_module and in_skill_dir
  local function is_skill()
    error(fmt("require: '%s' is a skill: name it in depends_skills = {\"%s\"} and call it " ..
              "from a SkillJumpState (skills={{%s}})", name, name, name), 3)
  end
  if own and (h.load_error or h.fsm or h.env and rawget(h.env, "name") ~= nil) then is_skill() end
  if not text then
    error(fmt("module '%s' is not available in skills: require loads only the Lua files of " ..
              "the skill and module directories (%s); to use another skill, name it in " ..
              "depends_skills = {\"skill\"} and call it from a SkillJumpState " ..
              "(skills={{skill}})", name, path), 2)
  end
  local env = helper_env(name)
  local chunk, err = load(text, "@" .. path, "t", env)
  if not chunk then error(err, 0) end
  local outer = loading
  requiring[name], loading = true, nil
  local ok, ret = raw_pcall(chunk, name)
  requiring[name], loading = nil, outer
  -- A skill file not loaded yet: it declares a skill (or makes a state machine, which only a
  -- skill file may).
  if own and ((ok and (rawget(env, "name") ~= nil or rawget(env, "fsm") ~= nil or
                       rawget(env, "execute") ~= nil)) or
              (not ok and type(ret) == "string" and ret:find("SkillHSM:new can only be called",
                                                             1, true))) then
    is_skill()
  end
  if not ok then error(ret, 0) end
  if ret == nil then ret = env end
  modules[name] = ret
  return ret
end

-- States -------------------------------------------------------------------------------------
local JumpState = readonly({kind = "jump"}, "JumpState")
local SkillJumpState = readonly({kind = "skill"}, "SkillJumpState")
base.JumpState, base.SkillJumpState = JumpState, SkillJumpState

local SkillHSM = {}
SkillHSM.__metatable = false  -- getmetatable(fsm) must not hand out the shared class
-- fsm.result: the exercises and the string's result() read it as text, and a table would show
-- its address. Its first assignment (the key is absent until then, and again after each reset)
-- is checked here, at the skill's line; a later one that puts another type in its place is
-- caught when the skill ends (E.run_cycle). __index stays a table: a function there would run on
-- every miss (fsm.error, fsm.debug, ... are read in every step).
SkillHSM.__index = SkillHSM
SkillHSM.__newindex = function(fsm, k, v)
  if k == "result" and v ~= nil and type(v) ~= "string" and type(v) ~= "number" then
    error(fmt("fsm.result must be a string (e.g. \"1.20 3.40\") or a number, not a %s: " ..
              "self.fsm.result = string.format(\"%%.2f %%.2f\", x, y)", type(v)), 2)
  end
  rawset(fsm, k, v)
end
base.SkillHSM = readonly(SkillHSM, "SkillHSM")

-- self.args of a state that runs no sub-skill of that name is never read: a warning at the line
-- that sets it (once per state and key).
local function args_watch(st)
  local warned = {}
  return {__newindex = function(t, k, v)
    rawset(t, k, v)
    if warned[k] then return end
    local names = {}
    for i, h in ipairs(subskills_of[st] or {}) do
      if h.name == k then return end
      names[i] = h.name
    end
    warned[k] = true
    local what = fmt("%s: state '%s' sets self.args[\"%s\"]", st.fsm.name, st.name, tostring(k))
    if #names == 0 then
      log(2, fmt("%s: %s, but it runs no sub-skill (it is a JumpState), so the arguments are " ..
                 "ignored: make it a SkillJumpState (skills={{%s}}, final_to=...) or drop " ..
                 "self.args", where(2), what, type(k) == "string" and k or "skill"))
    else
      log(2, fmt("%s: %s, but it runs only %s, so the arguments are ignored%s: " ..
                 "self.args[\"%s\"] = {...}", where(2), what, concat(names, ", "),
                 did_you_mean(k, names), names[1]))
    end
  end}
end

local function new_state(fsm, name, kind)
  local st = {name = name, fsm = fsm, kind = kind, transitions = {}, preconds = {}, args = {},
              entered_ns = 0, visit = 0}
  st.args_mt = args_watch(st)
  fsm.states[name] = st
  fsm.state_list[#fsm.state_list + 1] = st
  return st
end

function SkillHSM:new(o)
  if type(o) ~= "table" or type(o.start) ~= "string" then
    error("SkillHSM:new{...} needs start=\"STATE\", the state the skill begins in: " ..
          "fsm = SkillHSM:new{name=name, start=\"STATE\"}", 2)
  end
  if not loading then error("SkillHSM:new can only be called while a skill file loads", 2) end
  local fsm = setmetatable({name = o.name or loading.name, start = o.start, debug = o.debug,
                            states = {}, state_list = {}, defaults = {}, vars = {},
                            closure = {}, where = where(2), step_id = 0},
                           SkillHSM)
  fsms[fsm] = loading
  fsm.cond_env = setmetatable(fsm.closure, {__index = loading.env})
  fsm.final = new_state(fsm, "FINAL", "final")
  fsm.failed = new_state(fsm, "FAILED", "failed")
  return fsm
end

local function resolve_subskill(fsm, spec, lvl)
  local s = spec[1]
  local h = type(s) == "string" and handles[s] or real_of[s]
  if not h then error(fmt("skills: entry %s is not a skill", tostring(s)), lvl) end
  if fsms[fsm].bindings[h.name] ~= proxies[h.name] then
    error(fmt("skill '%s' is used but not declared in depends_skills", h.name), lvl)
  end
  return h
end

function SkillHSM:define_states(spec)
  local skill = fsms[self]
  local export = spec.export_to or skill.env
  for _, st in ipairs{self.final, self.failed} do
    if rawget(export, st.name) == nil then rawset(export, st.name, st) end
  end
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
    st.where = where(2)
    if class == SkillJumpState then
      if type(e.skills) ~= "table" or #e.skills == 0 then
        error(fmt("SkillJumpState '%s' needs skills={{skill}, ...}", name), 2)
      end
      -- subskills_of[st]: the engine's, the real handles; st.skills: Fawkes' self.skills[i], one
      -- table per sub-skill holding its proxy at [1] and its arguments (the static ones of the
      -- definition, and what init() sets: self.skills[1].place = ...). They stay set from one
      -- entry of the state to the next, as in Fawkes, where they were the definition's own table.
      local subskills = {}
      st.skills, st.call_args = {}, {}
      for i, s in ipairs(e.skills) do
        local def = type(s) == "table" and not s.is_skill and s or {s}
        local h = resolve_subskill(self, def, 3)
        subskills[i] = h
        local entry = {proxies[h.name]}
        for k, v in pairs(def) do
          if k ~= 1 then entry[k] = v end
        end
        st.skills[i] = entry
      end
      subskills_of[st] = subskills
      st.final_to, st.fail_to = e.final_to, e.fail_to or "FAILED"
      if type(st.final_to) ~= "string" then
        error(fmt("SkillJumpState '%s' needs final_to=\"STATE\"", name), 2)
      end
    end
    -- timeout= of a state definition is llsfsim's; Fawkes' skiller (2013) ignored it, and so
    -- does a file written for Fawkes (module(..., skillenv.module_init)).
    if e.timeout ~= nil and not skill.fawkes_style then pending[#pending + 1] = {st, e.timeout} end
    rawset(export, name, st)
  end
  for _, st in ipairs(self.state_list) do
    for _, f in ipairs{"final_to", "fail_to"} do
      if st[f] and not self.states[st[f]] then
        error(fmt("state '%s': %s=\"%s\" names an %s", st.name, f, st[f],
                  unknown_state(self, st[f])), 2)
      end
    end
  end
  -- State timeouts: timeout={secs, "TO", error="..."}.
  for _, p in ipairs(pending) do
    local st, t = p[1], p[2]
    local secs, to = t, "FAILED"
    if type(t) == "table" then secs, to = t[1], t[2] or "FAILED" end
    if type(secs) ~= "number" then
      error(fmt("state '%s': timeout must be secs or {secs, \"STATE\"}", st.name), 2)
    end
    if not self.states[to] then
      error(fmt("state '%s': timeout goes to an %s", st.name, unknown_state(self, to)), 2)
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
  if not f then
    -- A lone `=` (an assignment, not a comparison) is the usual cause: say so, not "')' expected".
    local bare = (" " .. c .. " "):gsub("[=~<>]=", "  ")
    if bare:find("=", 1, true) then
      error(fmt("bad %s \"%s\": `=` assigns; a condition compares with `==` (or `~=`)", what, c),
            lvl)
    end
    error(fmt("bad %s \"%s\": %s", what, c, err), lvl)
  end
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
    if #self.state_list <= 2 and not (self.states[to] and (not from or self.states[from])) then
      error("add_transitions: no state is defined yet: call fsm:define_states{...} first", 2)
    end
    if from and not self.states[from] then
      error(fmt("add_transitions: {\"%s\", \"%s\"} starts in an %s", from, tostring(to),
                unknown_state(self, from)), 2)
    end
    if type(to) ~= "string" then
      error(fmt("add_transitions: entry %d needs the state to go to: {\"FROM\", \"TO\", ...}", i),
            2)
    end
    if not self.states[to] then
      error(fmt("add_transitions: {%s\"%s\"} goes to an %s", from and fmt("\"%s\", ", from) or "",
                to, unknown_state(self, to)), 2)
    end
    local tr = {from = from, to = self.states[to], desc = t.desc, error = t.error, where = loc}
    local text
    if fsms[self].fawkes_style and from then
      -- As Fawkes' add_transitions: the condition is t[3] or cond=; precond=COND is the
      -- condition of a transition and a precondition both, precond=true makes cond one too,
      -- precond_only=COND a precondition only.
      local c = t[3]
      if c == nil then c = t.cond end
      if type(t.precond) ~= "boolean" and type(t.precond_only) ~= "boolean" then
        if c == nil then c = t.precond end
        if c == nil then c = t.precond_only end
      end
      text = c
      if c ~= nil then
        local f = compile_cond(self, c, "cond", loc, 3)
        if t.precond_only then
          tr.precond = f
        else
          tr.cond = f
          if t.precond then tr.precond = f end
        end
      end
    else
      if t.cond ~= nil then tr.cond = compile_cond(self, t.cond, "cond", loc, 3) end
      if t.precond ~= nil then tr.precond = compile_cond(self, t.precond, "precond", loc, 3) end
    end
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
    text = text or t.cond or t.cond_and_precond or t.precond
    tr.label = tr.label or tr.desc or (type(text) == "string" and text) or "condition"
    -- As written, for messages: {"CHECK", "FINAL", cond="vars.done"}.
    local parts = {fmt("\"%s\"", from or "*"), fmt("\"%s\"", to)}
    for _, key in ipairs({"cond", "cond_and_precond", "precond"}) do
      local c = t[key]
      if c == true then
        parts[#parts + 1] = key .. "=true"
      elseif type(c) == "string" then
        parts[#parts + 1] = fmt("%s=\"%s\"", key, c)
      elseif c ~= nil then
        parts[#parts + 1] = key .. "=" .. (t.desc and fmt("<function: %s>", t.desc) or "<function>")
      end
    end
    if t.timeout ~= nil then parts[#parts + 1] = fmt("timeout=%g", tr.timeout_ns / 1e9) end
    tr.shown = "{" .. concat(parts, ", ") .. "}"
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

local spec_args

-- A condition reading a key of vars that nothing set (vars.arived for vars.arrived) never holds:
-- the keys conditions missed are kept per state machine (key -> transition), for the check of a
-- state that waits long (fsm_step) and the report of a skill still running at the end.
local cond_fsm, cond_tr = nil, nil  -- the state machine and transition whose condition runs
-- (One table for every skill of the interpreter: __metatable hides it, or one skill could change
-- how every other's conditions read vars.)
local vars_mt = {__metatable = false, __index = function(_, k)
  local fsm = cond_fsm
  if fsm and type(k) == "string" then
    local m = fsm.misses
    if not m then
      m = {}
      fsm.misses = m
    end
    if m[k] == nil then m[k] = cond_tr end
  end
  return nil
end}

local function holds(c, st, fsm)
  if c == true then return true end
  return c(st, fsm.vars, fsm)
end

-- Sub-skills of a SkillJumpState: next state and error text once they are done.
local function run_subskills(fsm, st)
  local all_final = true
  local skills = subskills_of[st]
  for i = 1, #skills do
    local h = skills[i]
    local status = call_skill(h, st.call_args[i] or st.args[h.name] or fsm.vars)
    if status == S_FAILED then
      return fsm.states[st.fail_to], fmt("%s()/%s failed: %s", st.name, h.name,
                                          tostring(h.error)), h.reason
    elseif status ~= S_FINAL then
      all_final = false
    end
  end
  if all_final then return fsm.states[st.final_to], nil end
  return nil, nil
end

-- The arguments of each sub-skill of `st` as Fawkes' SkillJumpState made them on entry: the
-- keys of self.skills[i] other than [1], merged with self.args[name] (its keys win); neither:
-- the sub-skill gets the skill's own fsm.vars (st.call_args[i] nil, self.args read per call).
spec_args = function(st)
  for i, h in ipairs(subskills_of[st]) do
    local spec, args = st.skills[i], nil
    for k, v in pairs(spec) do
      if k ~= 1 then
        args = args or {}
        args[k] = v
      end
    end
    local a = args and st.args[h.name]
    if type(a) == "table" then
      for k, v in pairs(a) do args[k] = v end
    end
    st.call_args[i] = args
  end
end

-- Enters `st` (following preconditions) and returns the state actually entered.
local function enter(fsm, st, now)
  for _ = 1, kMaxStatesPerStep do
    local jumped = false
    for _, tr in ipairs(st.preconds) do
      fsm.running = st
      if holds(tr.precond, st, fsm) then
        if tr.to == fsm.failed and not fsm.error then
          -- A function precondition may have said why (self.fsm.error): keep its words.
          fsm.error = fsm.error or tr.error or fmt("%s: precondition %s", st.name, tr.label)
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
  st.waited = nil
  st.args = setmetatable({}, st.args_mt)
  st.error, st.reason = nil, nil
  fsm.current = st
  fsm.running = st
  local subskills = subskills_of[st]
  if subskills then
    for _, h in ipairs(subskills) do reset_skill(h) end
  end
  if st.init then st:init() end
  if subskills then spec_args(st) end
  return st
end

-- `reason`: a failed sub-skill's reason code, taken over with its error (fail_to).
local function leave(fsm, st, to, tr, err, reason)
  if st.exit then fsm.running = st; st:exit() end
  local e = err or (tr and tr.error)
  if to == fsm.failed and not fsm.error then
    fsm.error = e or fmt("%s: %s", st.name, tr and tr.label or "failed")
    if err and reason and fsm.reason == nil then fsm.reason = reason end
  elseif e then
    st.error = e
    if err then st.reason = reason end
  end
  if fsm.debug then
    log(0, fmt("%s: %s -> %s (%s)", fsm.name, st.name, to.name, tr and tr.label or "skills"))
  end
end

-- One FSM step: loop hook, sub-skills and transitions of the current state; a state entered in
-- this step runs in the same step unless it already ran in it.
local kSpinNs, kSpinTransitions = 2 * 1000000000, 20

-- A state machine that switches states in every step for kSpinNs of game time (at least
-- kSpinTransitions switches) while no sub-skill runs and no timeout fires never waits for
-- anything: e.g. two states bouncing with cond=true. One warning per call of the skill.
local watch_misses  -- below

local function watch_spin(fsm, now, path, trs, progress)
  if not trs or #trs == 0 or progress then
    if fsm.spin ~= nil then fsm.spin = nil end
    return
  end
  local sp = fsm.spin
  if not sp then
    sp = {since = now, n = 0}
    fsm.spin = sp
  end
  sp.n = sp.n + #trs
  if sp.warned or sp.n < kSpinTransitions or now - sp.since < kSpinNs then return end
  sp.warned = true
  local tr = nil  -- the first transition, or the first with cond=true
  for _, t in ipairs(trs) do
    if type(t) == "table" then
      if t.cond == true then tr = t; break end
      tr = tr or t
    end
  end
  if not tr then return end
  log(2, fmt("%s: %s: states %s keep switching without waiting (%d switches in %.1f s of game " ..
             "time, no sub-skill running, no timeout): the transition {\"%s\", \"%s\", %s} " ..
             "fires at once; make the state wait for something (cond=\"...\", timeout=SECS)",
             tr.where, fsm.name, concat(path, " -> "), sp.n, (now - sp.since) / 1e9,
             tr.from or "*", tr.to.name, tr.cond == true and "cond=true" or tr.label))
end

-- The keys of vars the conditions of `st` read and nothing has set, each with the set key near
-- enough to be what was meant (nil if none is): {{"arived", "arrived", tr}, ...} in name order;
-- and the keys that are set, in name order.
local function missed_keys(fsm, st)
  local out = {}
  local set = {}
  for k in next, fsm.vars do
    if type(k) == "string" then set[#set + 1] = k end
  end
  for k, tr in pairs(fsm.misses or {}) do
    if (tr.from == nil or tr.from == st.name) and rawget(fsm.vars, k) == nil then
      out[#out + 1] = {k, nearest(k, set), tr}
    end
  end
  table.sort(out, function(a, b) return a[1] < b[1] end)
  table.sort(set)
  return out, set
end

-- A state that has waited kWaitNs on a condition that reads a key of vars nothing set, while a
-- key near it is set: a typo, so the condition never holds. One warning per key and entry. (A
-- key with no set key near it may still be set later, by a loop that finds something: only the
-- report of a skill still running at the end names it.)
local kWaitNs = 5 * 1000000000
watch_misses = function(fsm, st, now)
  for _, m in ipairs(missed_keys(fsm, st)) do
    local k, near, tr = m[1], m[2], m[3]
    if near then
      log(2, fmt("%s: %s: state '%s' has waited %.0f s on %s, which reads vars.%s: nothing " ..
                 "set it (did you mean vars.%s?), so the condition never holds", tr.where,
                 fsm.name, st.name, (now - st.entered_ns) / 1e9, tr.shown, k, near))
    end
  end
end

local cycle_now_ns  -- the game time of the running cycle (E.run_cycle)

local function fsm_step(fsm)
  local now = cycle_now_ns
  fsm.step_id = fsm.step_id + 1
  local st = fsm.current or enter(fsm, fsm.states[fsm.start], now)
  -- The states passed and the transitions taken (for watch_spin), made on the first
  -- transition: most steps stay in their state and allocate nothing.
  local first, path, trs, progress = st.name, nil, nil, false
  for _ = 1, kMaxStatesPerStep do
    if st.kind == "final" or st.kind == "failed" or st.visit == fsm.step_id then break end
    st.visit = fsm.step_id
    fsm.running = st
    if st.loop then st:loop() end
    local to, tr, err, sub_reason = nil, nil, nil, nil
    if fsm.error == nil then
      -- (A SkillJumpState; its kind, one field read, and not subskills_of[st]: no lookup more
      -- in every step than when the handles were a field of the state.)
      if st.kind == "skill" then
        progress = true
        to, err, sub_reason = run_subskills(fsm, st)
      end
      -- The state's transitions, then the defaults: the first whose timeout passed or whose
      -- condition holds (written out, no call per transition: this runs in every step).
      local list = not to and st.transitions or nil
      cond_fsm = fsm
      while list do
        for i = 1, #list do
          local t = list[i]
          local c = t.cond
          cond_tr = t
          if (t.timeout_ns and now - st.entered_ns >= t.timeout_ns) or c == true or
             (c ~= nil and c(st, fsm.vars, fsm)) then
            to, tr = t.to, t
            break
          end
        end
        list = not to and list ~= fsm.defaults and fsm.defaults or nil
      end
      cond_fsm, cond_tr = nil, nil
    else
      to = fsm.failed  -- the skill set fsm.error: failure
    end
    if not to then break end
    if not path then path, trs = {first}, {} end
    if tr then
      trs[#trs + 1] = tr
      if tr.timeout_ns then progress = true end
    else  -- what took it there, for skill_state's `via`
      trs[#trs + 1] = err and "fail_to" or (st.kind == "skill" and fsm.error == nil and "final_to") or
                      "error"
    end
    leave(fsm, st, to, tr, err, sub_reason)
    st = enter(fsm, to, now)
    path[#path + 1] = st.name
  end
  if trs or fsm.spin ~= nil then watch_spin(fsm, now, path, trs, progress) end
  -- The states this step went through (nil: it stayed), for skill_state, and what took it from
  -- each to the next (a transition or "final_to", ...). (Nil is written only over a value:
  -- written to an absent key it would still call SkillHSM.__newindex, twice in most steps.)
  if path or fsm.passed ~= nil then fsm.passed = path end
  if trs or fsm.passed_by ~= nil then fsm.passed_by = trs end
  if not path and fsm.misses and not st.waited and now - st.entered_ns >= kWaitNs then
    st.waited = true
    watch_misses(fsm, st, now)
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
    -- At the skill's execute (where the `return` is missing or wrong), not at this line.
    local info = debug_getinfo(h.env.execute, "S")
    error(fmt("%s:%d: %s: execute() returned %s, expected S_RUNNING, S_FINAL or S_FAILED%s",
              info.short_src, info.linedefined, h.name, tostring(s),
              s == nil and " (a path through execute() without a `return`?)" or ""), 0)
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
    h.fsm.reason = nil
    -- fsm.passed(_by) stay: the last step's states are still to be reported when the string
    -- ended in it (its step number tells them from a new step's).
    h.fsm.misses = nil
    h.fsm.spin = nil
    for _, st in ipairs(h.fsm.state_list) do st.visit = 0 end
  end
  h.active, h.status, h.error, h.vars, h.reason = false, S_INACTIVE, nil, nil, nil
  for i = #h.children, 1, -1 do
    local c = h.children[i]
    h.children[i] = nil
    c.child_of = nil
    reset_skill(c)
  end
end

call_skill = function(h, args)
  if h.is_module then
    error(fmt("'%s' is no skill: %s defines none (a helper module for require)", h.name,
              h.path or h.name), 0)
  end
  if h.load_error then
    E.raised_reason = h.load_reason or "error"
    error(fmt("skill '%s' is not available: %s", h.name, h.load_error), 0)
  end
  if h.in_call then error(fmt("recursive call of skill '%s'", h.name), 0) end
  if args ~= nil and args ~= h.args_seen then  -- (a sub-skill gets the same table each step)
    if type(args) ~= "table" then
      error(fmt("skill '%s': arguments must be a table, e.g. %s{key=value}", h.name, h.name), 0)
    end
    h.args_seen = args
  end
  if not h.active then
    local vars = {}
    for k, v in pairs(args or {}) do vars[k] = v end
    h.active, h.status, h.error = true, S_RUNNING, nil
    if h.fsm then h.fsm.vars = setmetatable(vars, vars_mt) else h.vars = vars end
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
  local fsm, ok, status, err = h.fsm, nil, nil, nil
  if fsm then  -- step(h), one call less
    ok, status = raw_pcall(fsm_step, fsm)
    if ok then err = fsm.error end
  else
    ok, status, err = raw_pcall(step, h)
  end
  caller, h.in_call, depth = outer, false, depth - 1
  cond_fsm, cond_tr = nil, nil  -- a condition that raised an error left them set
  if ok then
    h.status = status
    if status == S_FAILED then
      h.error = err == nil and "failed" or error_text(err)
      -- The skill's own failure: the reason it declared (fsm.reason), if any.
      local r = fsm and fsm.reason
      if r ~= nil and not kDeclaredReasons[r] then
        h.error = fmt("%s; fsm.reason must be \"aborted\" or \"not-found\" (or a sub-skill's " ..
                      "reason), not %s", h.error, tostring(r))
        h.reason = "error"
      else
        h.reason = r or "failed"
      end
    end
    return status
  end
  local running = h.fsm and h.fsm.running
  h.reason = exhausted() and "budget" or E.raised_reason or "error"
  E.raised_reason = nil
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

-- Entry points for the C++ engine (E: declared at the top) -----------------------------------

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
  if modules[name] ~= nil then  -- loaded by a require already: a helper module
    h.is_module = true
    return nil
  end
  h.env = module_env(h)
  loading = h
  return h.env
end

-- Checks a loaded module's declarations; errors name the file (and line where one is known).
-- `returned`: what the file returned (a helper module's value for require, as require gives it).
function E.finish_module(name, returned)
  local h = handles[name]
  loading = nil
  local env = h.env
  -- What is missing has no line of its own: the message names the line of `name = ...` (where
  -- the declarations go), else line 1.
  local at = h.name_where or (h.path .. ":1")
  local function fail(msg) error(at .. ": " .. msg, 0) end
  -- A file that declares nothing of a skill is a helper module (Fawkes loaded only the files
  -- its skill space named): not a skill, and what require returns for its name.
  local declared = false
  for _, k in ipairs{"name", "fsm", "documentation", "depends_skills", "depends_interfaces",
                     "execute"} do
    if rawget(env, k) ~= nil then declared = true end
  end
  if not declared then
    h.is_module = true
    if returned == nil then returned = env end
    modules[h.name] = returned
    return
  end
  if rawget(env, "name") == nil then
    fail(fmt("the skill declares no 'name': add name = \"%s\" at the top of the file", h.name))
  end
  if type(rawget(env, "documentation")) ~= "string" then
    fail("the skill declares no 'documentation' string: add documentation = [==[what the " ..
         "skill does]==] next to name = ...")
  end
  local fsm = rawget(env, "fsm")
  if fsm ~= nil then
    if not fsms[fsm] then fail("'fsm' must be a SkillHSM: fsm = SkillHSM:new{name=name, start=\"STATE\"}") end
    if #fsm.state_list <= 2 and not fsm.states[fsm.start] then
      error(fmt("%s: the state machine has no states: fsm:define_states{...} is missing " ..
                "(start state '%s' is not defined)", fsm.where, fsm.start), 0)
    end
    if not fsm.states[fsm.start] then
      error(fmt("%s: start=\"%s\" names an %s", fsm.where, fsm.start,
                unknown_state(fsm, fsm.start)), 0)
    end
    h.fsm = fsm
    -- A transition after one with cond=true from the same state never fires (the first whose
    -- condition holds is taken): warn at load.
    for _, st in ipairs(fsm.state_list) do
      local always = nil
      for _, tr in ipairs(st.transitions) do
        if always then
          log(2, fmt("%s: %s: the transition %s can never fire: %s before it has cond=true and " ..
                     "is always taken first; put it before that one, or drop it", tr.where,
                     h.name, tr.shown, always.shown))
        elseif tr.cond == true then
          always = tr
        end
      end
    end
    -- A state nothing leaves (no transition, timeout, precondition or sub-skill, no transition
    -- of every state) would only show as "still running" at the end: warn at load.
    if #fsm.defaults == 0 then
      for _, st in ipairs(fsm.state_list) do
        if st.kind ~= "final" and st.kind ~= "failed" and not subskills_of[st] and
           #st.transitions == 0 and #st.preconds == 0 then
          log(2, fmt("%s: %s: state '%s' has no way out: no transition, timeout or sub-skill " ..
                     "leaves it, so the skill would stay there; add one (fsm:add_transitions" ..
                     "{{\"%s\", \"STATE\", cond=...}} or timeout=SECS)", st.where or at, h.name,
                     st.name, st.name))
        end
      end
    end
  elseif type(rawget(env, "execute")) ~= "function" then
    fail("the skill has no state machine: add fsm = SkillHSM:new{name=name, start=\"STATE\"} " ..
         "and its fsm:define_states{...} (or an execute() function)")
  end
  h.documentation = env.documentation
end

-- A Fawkes skill space: the init.lua of a skill directory names its skills with
-- skillenv.use_skill("skills.<space>.<name>"). Runs it with only what such a file uses and
-- returns the names (the last part of each), or nil and why it could not run.
function E.skill_space(text, chunkname)
  local names = {}
  local function use_skill(m)
    if type(m) == "string" then names[#names + 1] = m:match("([^.]+)$") end
  end
  local env = {skillenv = {use_skill = use_skill},
               fawkes = {modinit = {register_all = noop, module_init = noop}},
               module = noop, require = function() return {} end, print = noop, printf = noop}
  local chunk, err = load(text, chunkname, "t", env)
  if not chunk then return nil, err end
  local ok, e = raw_pcall(chunk)
  if not ok then return nil, error_text(e) end
  return names
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
          if handles[dep].is_module then
            h.load_error = fmt("depends_skills: '%s' is no skill (a helper module)", dep)
            changed = true
            break
          elseif handles[dep].load_error then
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
  if not h or h.is_module then return nil end
  local state = h.fsm and h.fsm.current and h.fsm.current.name or ""
  return h.status, h.error or "", state, h.load_error or "", h.path or "",
         h.documentation or "", concat(h.depends, ",")
end

-- Only the state (SkillBrain asks it in every cycle while a state listener is set), the states
-- the last step went through ("GO,NEXT,GO"; nil if it stayed in one), so that states passed
-- within one cycle are seen too, and that step's number (a step not taken reports nothing new).
function E.skill_state(name, with_via)
  local h = handles[name]
  local fsm = h and h.fsm
  if not fsm then return "" end
  local via = nil
  if with_via and fsm.passed_by then  -- what took the step from each state to the next
    local texts = {}
    for i, t in ipairs(fsm.passed_by) do
      texts[i] = type(t) == "table" and fmt("%s at %s", t.shown, t.where) or
                 t == "final_to" and "its sub-skills ended FINAL (final_to)" or
                 t == "fail_to" and "a sub-skill FAILED (fail_to)" or "fsm.error was set"
    end
    via = concat(texts, "\n")
  end
  return fsm.current and fsm.current.name or "", fsm.passed and concat(fsm.passed, ",") or nil,
         fsm.step_id, via
end

-- Why a running skill has not ended, for a report at the end of a game: the state it is in,
-- since when (game seconds) and what would take it out, with the keys of vars its conditions
-- read but nothing set. nil when it is not running in a state machine.
function E.skill_wait(name)
  local h = handles[name]
  local fsm = h and h.fsm
  local st = fsm and fsm.current
  if not st or st.kind == "final" or st.kind == "failed" or h.status ~= S_RUNNING then return nil end
  local out = fmt("in state %s since %.2f s", st.name, st.entered_ns / 1e9)
  if subskills_of[st] then
    local names = {}
    for i, h in ipairs(subskills_of[st]) do names[i] = h.name end
    return out .. fmt(", its sub-skill(s) %s still running", concat(names, ", "))
  end
  local waits = {}
  for _, tr in ipairs(st.transitions) do waits[#waits + 1] = fmt("%s (%s)", tr.shown, tr.where) end
  for _, tr in ipairs(fsm.defaults) do waits[#waits + 1] = fmt("%s (%s)", tr.shown, tr.where) end
  out = out .. ", waiting for " .. (#waits > 0 and concat(waits, " or ") or "nothing: no way out")
  local missed, set = missed_keys(fsm, st)
  for _, m in ipairs(missed) do
    if m[2] then
      out = out .. fmt("; vars.%s is never set (did you mean vars.%s?)", m[1], m[2])
    else
      -- No set key is near it: name what is set, so a misspelling or a missing assignment shows.
      local shown = {}
      for i = 1, math.min(#set, 8) do shown[i] = "vars." .. set[i] end
      out = out .. fmt("; vars.%s is never set (%s)", m[1], #set == 0 and
                         "the skill has set no key of vars" or
                         "what is set: " .. concat(shown, ", ") .. (#set > 8 and ", ..." or ""))
    end
  end
  return out
end

local string_env = setmetatable({}, {
  __index = function(t, k)
    local v = proxies[k] or base[k]
    if v == nil then
      E.raised_reason = "unknown-skill"
      error(fmt("unknown skill '%s'", tostring(k)), 2)
    end
    rawset(t, k, v)
    return v
  end,
  __metatable = false})

function E.compile(s)
  return load(s, "=skill string", "t", string_env)
end

local fawkes_poll = fawkes.poll

function E.run_cycle(chunk)
  E.raised_reason = nil
  cycle_id = cycle_id + 1
  cycle_now_ns = now_ns()
  fawkes_poll()
  for i = #called, 1, -1 do called[i] = nil end
  depth, caller = 0, nil
  chunk()
  local status, errors, results, reason = S_FINAL, nil, nil, nil
  for i = 1, #called do
    local h = called[i]
    local r = h.fsm and h.fsm.result
    if r ~= nil and type(r) ~= "string" and type(r) ~= "number" then  -- only by rawset
      h.status = S_FAILED
      h.error = fmt("fsm.result must be a string (e.g. \"1.20 3.40\") or a number, not a %s",
                    type(r))
      h.reason = "error"
    elseif r ~= nil and h.status ~= S_RUNNING then
      results = results or {}
      results[#results + 1] = tostring(r)
    end
    if h.status == S_FAILED then
      status = S_FAILED
      reason = reason or h.reason or "failed"
      errors = errors or {}
      -- (named once: the library's skills start their own messages with their name)
      local e, prefix = tostring(h.error), h.name .. ": "
      errors[#errors + 1] = e:sub(1, #prefix) == prefix and e or prefix .. e
    elseif h.status == S_RUNNING and status ~= S_FAILED then
      status = S_RUNNING
    end
  end
  return status, errors and concat(errors, "; ") or nil, results and concat(results, "; ") or "",
         reason
end

-- The blackboard interfaces skills wrote since the last call (fawkes.lua, F.written).
function E.written_interfaces()
  return fawkes.written()
end

-- The agent's side of the blackboard (fawkes.lua: F.snapshot, F.set, F.send, F.state).
E.blackboard_state = fawkes.state
function E.interface_snapshot(type_name, id) return fawkes.snapshot(type_name, id) end
function E.interface_set(type_name, id, values) return fawkes.set(type_name, id, values) end
function E.interface_send(type_name, id, name, values)
  return fawkes.send(type_name, id, name, values)
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
