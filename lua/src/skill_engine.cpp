// SPDX-License-Identifier: MIT
// SkillEngine: builds the sandboxed interpreter, loads skill files, runs skill strings under an
// instruction budget, and reloads changed files between skill strings.
#include "llsf/lua/skill_engine.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include <sys/stat.h>

#include "engine_impl.h"
#include "llsf/core/assert.h"
#include "llsf/core/error.h"
#include "llsf/core/input_file.h"
#include "llsf/core/text.h"

namespace llsf::lua {

namespace fs = std::filesystem;

const char* to_string(SkillStatus status) {
  switch (status) {
    case SkillStatus::kInactive:
      return "INACTIVE";
    case SkillStatus::kFinal:
      return "FINAL";
    case SkillStatus::kRunning:
      return "RUNNING";
    case SkillStatus::kFailed:
      return "FAILED";
  }
  return "?";
}

const char* to_string(FailReason reason) {
  switch (reason) {
    case FailReason::kNone:
      return "none";
    case FailReason::kFailed:
      return "failed";
    case FailReason::kAborted:
      return "aborted";
    case FailReason::kNotFound:
      return "not-found";
    case FailReason::kUnknownSkill:
      return "unknown-skill";
    case FailReason::kBadString:
      return "bad-string";
    case FailReason::kError:
      return "error";
    case FailReason::kBudget:
      return "budget";
  }
  return "none";
}

namespace {

// The reason the prelude names (E.run_cycle's fourth result, E.raised_reason); kError for a
// name it should not give.
FailReason reason_named(const char* name) {
  if (name == nullptr) return FailReason::kError;
  for (const FailReason r : {FailReason::kFailed, FailReason::kAborted, FailReason::kNotFound,
                             FailReason::kUnknownSkill, FailReason::kError, FailReason::kBudget}) {
    if (std::strcmp(name, to_string(r)) == 0) return r;
  }
  return FailReason::kError;
}

}  // namespace

// ---- config ------------------------------------------------------------------------------------

namespace {
// Upper bounds of the budgets: far above any skill's need (the defaults are 1,000,000
// instructions and 64 MiB), low enough that one cycle stays seconds and the heap fits the machine.
constexpr double kMaxInstructionBudget = 1e10;
constexpr double kMaxMemoryBytes = 16.0 * (1LL << 30);
}  // namespace

void SkillEngineConfig::validate() const {
  core::require("skill engine: rate_hz", rate_hz, core::in_range(0.1, 10000.0));
  core::require("skill engine: instruction_budget", static_cast<double>(instruction_budget),
                core::in_range(1000, kMaxInstructionBudget));
  core::require("skill engine: memory_limit_bytes", static_cast<double>(memory_limit_bytes),
                core::in_range(1 << 20, kMaxMemoryBytes));
  core::require("skill engine: allocation_budget_bytes",
                static_cast<double>(allocation_budget_bytes),
                core::in_range(1 << 20, kMaxMemoryBytes));
  core::require("skill engine: max_cycle_wall_s", max_cycle_wall_s, core::in_range(0.01, 3600.0));
  const auto check_dirs = [](const std::vector<std::string>& dirs, const char* what) {
    for (const std::string& dir : dirs) {
      std::error_code ec;
      if (!fs::is_directory(dir, ec)) {
        throw core::ConfigError(std::string("skill engine: ") + what + " '" + dir +
                                "' does not exist");
      }
    }
  };
  check_dirs(skill_dirs, "skill directory");
  check_dirs(module_dirs, "module directory");
  check_dirs(cfg_dirs, "cfg directory");
}

SkillEngineConfig SkillEngineConfig::from_config(const core::ConfigNode& node,
                                                 const std::string& base_dir) {
  node.require_map();
  SkillEngineConfig cfg;
  const core::ConfigNode dirs = node["skill_dirs"];
  if (dirs.defined()) {
    if (!dirs.is_sequence()) dirs.fail("expected a list of directories");
    for (const core::ConfigNode& d : dirs.elements()) {
      const fs::path dir(d.as_string());
      cfg.skill_dirs.push_back(dir.is_absolute() || base_dir.empty()
                                   ? dir.string()
                                   : (fs::path(base_dir) / dir).lexically_normal().string());
    }
  }
  // Each figure checked at its own key (validate() below repeats the checks for configs built
  // in code).
  // module_dirs, cfg_dirs: like skill_dirs (relative to the file).
  const auto read_dirs = [&](std::string_view key, std::vector<std::string>& out) {
    const core::ConfigNode list = node[key];
    if (!list.defined()) return;
    if (!list.is_sequence()) list.fail("expected a list of directories");
    for (const core::ConfigNode& d : list.elements()) {
      const fs::path dir(d.as_string());
      out.push_back(dir.is_absolute() || base_dir.empty()
                        ? dir.string()
                        : (fs::path(base_dir) / dir).lexically_normal().string());
    }
  };
  read_dirs("module_dirs", cfg.module_dirs);
  read_dirs("cfg_dirs", cfg.cfg_dirs);
  // fawkes_config: a tree of maps whose leaves are the values, flattened to "/a/b/c" paths.
  if (const core::ConfigNode tree = node["fawkes_config"]; tree.defined()) {
    tree.require_map();
    std::vector<std::pair<std::string, core::ConfigNode>> todo{{"", tree}};
    while (!todo.empty()) {
      auto [prefix, n] = todo.back();
      todo.pop_back();
      for (const std::string& key : n.keys()) {
        const core::ConfigNode v = n[key];
        if (v.is_map()) {
          todo.emplace_back(prefix + "/" + key, v);
        } else if (v.is_scalar()) {
          cfg.fawkes_config[prefix + "/" + key] = v.as_string();
        } else {
          v.fail("expected a value or a map of values (lists are not offered)");
        }
      }
    }
  }
  node.read("rate_hz", cfg.rate_hz, core::in_range(0.1, 10000.0));
  const auto read_int = [&](std::string_view key, std::int64_t& out, double lo, double hi) {
    const core::ConfigNode v = node[key];
    if (v.defined()) out = v.as_int(core::in_range(lo, hi));
  };
  read_int("instruction_budget", cfg.instruction_budget, 1000, kMaxInstructionBudget);
  read_int("memory_limit_bytes", cfg.memory_limit_bytes, 1 << 20, kMaxMemoryBytes);
  read_int("allocation_budget_bytes", cfg.allocation_budget_bytes, 1 << 20, kMaxMemoryBytes);
  node.read("max_cycle_wall_s", cfg.max_cycle_wall_s, core::in_range(0.01, 3600.0));
  node.read("hot_reload", cfg.hot_reload);
  std::int64_t seed = 0;
  node.read("random_seed", seed);
  cfg.random_seed = static_cast<std::uint64_t>(seed);
  node.no_other_keys();
  try {
    cfg.validate();
  } catch (const core::ConfigError& e) {
    node.fail(e.what());
  }
  return cfg;
}

// ---- interpreter plumbing
// ------------------------------------------------------------------------

namespace {

constexpr const char* kPreludeChunkName = "=llsf/prelude.lua";
constexpr const char* kFawkesChunkName = "=llsf/fawkes.lua";

// Where a refused allocation happened: the innermost frame of a skill file (chunk names "@path")
// and its current line, for Impl::explain(). Lua's memory error has no position, and Lua calls no
// message handler for it, so the stack is read here, in the allocator, before the error unwinds
// it. lua_getstack/lua_getinfo("Sl") only read CallInfos and prototypes and allocate nothing.
// Lua 5.4.4 (Debian bookworm) keeps the old stack valid while it allocates a bigger one; later
// releases turn stack pointers into offsets around that allocation, so there nothing is read.
void note_refusal(LuaHeap* heap) {
#if LUA_VERSION_RELEASE_NUM <= 50404
  if (heap->state == nullptr || !heap->in_call) return;
  lua_Debug ar{};
  for (int level = 0; lua_getstack(heap->state, level, &ar) != 0; ++level) {
    if (lua_getinfo(heap->state, "Sl", &ar) == 0) break;
    if (ar.currentline > 0 && ar.source != nullptr && ar.source[0] == '@') {
      std::snprintf(heap->refused_at, sizeof heap->refused_at, "%s:%d", ar.short_src,
                    ar.currentline);
      return;
    }
  }
#else
  static_cast<void>(heap);
#endif
}

// Allocator with a heap limit and an allocation budget: refusing an allocation makes Lua raise
// "not enough memory" (Impl::explain() names the budget and the line in the message).
void* limited_alloc(void* ud, void* ptr, std::size_t osize, std::size_t nsize) {
  auto* heap = static_cast<LuaHeap*>(ud);
  const std::int64_t old_size = ptr != nullptr ? static_cast<std::int64_t>(osize) : 0;
  if (nsize == 0) {
    std::free(ptr);
    heap->used -= old_size;
    return nullptr;
  }
  const std::int64_t grow = static_cast<std::int64_t>(nsize) - old_size;
  if (grow > 0) {
    if (heap->used + grow > heap->limit) {
      heap->limit_hit = true;
      note_refusal(heap);
      return nullptr;
    }
    if (heap->budget > 0 && heap->allocated + grow > heap->budget) {
      if (!heap->exhausted) {
        heap->exhausted = true;
        heap->budget = heap->allocated + kAllocationGrace;
      }
      note_refusal(heap);
      return nullptr;
    }
  }
  void* p = std::realloc(ptr, nsize);
  if (p != nullptr) {
    heap->used += grow;
    if (grow > 0) heap->allocated += grow;
  }
  return p;
}

int panic(lua_State* L) {
  // Only reachable through an unprotected call, which the engine never makes: a bug.
  const char* msg = lua_tostring(L, -1);
  LLSF_DEMAND_MSG(false, std::string("unprotected Lua error: ") + (msg ? msg : "?"));
  return 0;
}

std::int64_t hook_interval(const SkillEngineConfig& config) {
  return std::min(config.instruction_budget, kHookInterval);
}

// Count hook, every hook_interval() instructions: once the cycle used up its instruction budget,
// an error naming the running code's file:line. The count starts again from 0, so the code that
// catches it (the prelude) has a whole budget to unwind.
// Also the wall-time budget: one instruction can take long where no count sees it (comparing two
// long strings), so the clock is read at each call (about 20 ns per 1000 instructions).
void budget_hook(lua_State* L, lua_Debug* ar) {
  SkillEngine::Impl& e = SkillEngine::Impl::of(L);
  e.used += hook_interval(e.config);
  const bool out_of_time = std::chrono::steady_clock::now() > e.wall_deadline;
  if (e.used < e.config.instruction_budget && !out_of_time) return;
  e.used = 0;
  e.budget_exhausted = true;
  // Name the skill's line: the hook may fire in the prelude's code (a library wrapper, the DSL
  // runtime) running on the skill's behalf; then the nearest caller outside the prelude.
  const auto internal = [](const char* source) {
    return std::strcmp(source, kPreludeChunkName) == 0 ||
           std::strcmp(source, kFawkesChunkName) == 0;
  };
  lua_getinfo(L, "Sl", ar);
  lua_Debug caller{};
  for (int level = 1; internal(ar->source) && lua_getstack(L, level, &caller) != 0; ++level) {
    lua_getinfo(L, "Sl", &caller);
    if (caller.currentline > 0 && !internal(caller.source)) ar = &caller;
  }
  if (out_of_time) {
    const std::string secs = core::number_text(e.config.max_cycle_wall_s);
    lua_pushfstring(L,
                    "%s:%d: wall-time budget exhausted (%s s per cycle; long strings compared or "
                    "copied in a loop?)",
                    ar->short_src, ar->currentline, secs.c_str());
  } else {
    lua_pushfstring(
        L, "%s:%d: instruction budget exhausted (%I instructions per cycle; endless loop?)",
        ar->short_src, ar->currentline, static_cast<LUA_INTEGER>(e.config.instruction_budget));
  }
  lua_error(L);
}

bool any_budget_exhausted(const SkillEngine::Impl& e) {
  return e.budget_exhausted || e.heap.exhausted;
}

// pcall for skills: like the standard one, but an exhausted budget cannot be caught.
int sandbox_pcall(lua_State* L) {
  luaL_checkany(L, 1);
  const int status = lua_pcall(L, lua_gettop(L) - 1, LUA_MULTRET, 0);
  if (status != LUA_OK && any_budget_exhausted(SkillEngine::Impl::of(L))) return lua_error(L);
  lua_pushboolean(L, status == LUA_OK);
  lua_insert(L, 1);
  return lua_gettop(L);
}

int native_now_ns(lua_State* L) {
  lua_pushinteger(L, static_cast<lua_Integer>(SkillEngine::Impl::of(L).robot.now().ns()));
  return 1;
}

int native_exhausted(lua_State* L) {
  lua_pushboolean(L, any_budget_exhausted(SkillEngine::Impl::of(L)) ? 1 : 0);
  return 1;
}

// charge(cost, what): the prelude's library wrappers charge `cost` instructions of work; an
// exhausted budget is reported at the wrapper's caller (the skill's line).
int native_charge(lua_State* L) {
  const lua_Number cost = luaL_checknumber(L, 1);
  const char* what = luaL_checkstring(L, 2);
  // Costs beyond any budget (e.g. 2^60 elements) are clamped; NaN charges nothing.
  const std::int64_t c = cost >= 9.0e18 ? std::numeric_limits<std::int64_t>::max()
                         : cost > 0.0   ? static_cast<std::int64_t>(cost)
                                        : 0;
  charge(L, c, 2, what);
  return 0;
}

int native_log(lua_State* L) {
  const lua_Integer level = luaL_checkinteger(L, 1);
  std::size_t n = 0;
  const char* text = luaL_checklstring(L, 2, &n);
  SkillEngine::Impl& e = SkillEngine::Impl::of(L);
  if (!e.long_paths.empty()) {
    // Rare: the text again with whole paths, kept in a member (a Lua error below must not skip
    // a destructor) and on the Lua stack.
    e.cpp_error = e.full_paths(std::string(text, n));
    lua_pushlstring(L, e.cpp_error.data(), e.cpp_error.size());
    text = lua_tolstring(L, -1, &n);
  }
  if (!e.log_sink && e.loading_files) {
    if (e.pending_log.size() < kMaxPendingLog) {
      e.pending_log.emplace_back(static_cast<LogLevel>(std::clamp<lua_Integer>(level, 0, 3)),
                                 std::string(text, n));
    } else {
      ++e.pending_dropped;
    }
  } else if (e.log_sink) {
    bool failed = false;
    try {
      e.log_sink(static_cast<LogLevel>(std::clamp<lua_Integer>(level, 0, 3)),
                 std::string_view(text, n));
    } catch (const std::exception& ex) {
      e.cpp_error = ex.what();
      failed = true;
    }
    if (failed) return luaL_error(L, "log sink: %s", e.cpp_error.c_str());
  }
  return 0;
}

void open_lib(lua_State* L, const char* name, lua_CFunction fn) {
  luaL_requiref(L, name, fn, 1);
  lua_pop(L, 1);
}

std::string read_file(const std::string& path, std::string& error) {
  return core::try_read_input_file(path, core::kMaxSourceBytes, "Lua skill file", error)
      .value_or("");
}

bool is_identifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  if (from.empty() || from == to) return text;
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string pop_message(lua_State* L) {
  const char* msg = lua_tostring(L, -1);
  std::string out = msg != nullptr ? msg : "(error object is not a string)";
  lua_pop(L, 1);
  return out;
}

}  // namespace

SkillEngine::Impl::Impl(const SkillEngineConfig& cfg, RobotApi& robot_api)
    : config(cfg), robot(robot_api) {}

SkillEngine::Impl::~Impl() { close(); }

void SkillEngine::Impl::close() {
  heap.state = nullptr;
  if (L != nullptr) lua_close(L);
  L = nullptr;
  engine_ref = chunk_ref = LUA_NOREF;
  heap.used = 0;
}

std::string SkillEngine::Impl::full_paths(std::string text) const {
  for (const auto& [shortened, full] : long_paths) text = replace_all(text, shortened, full);
  return text;
}

const std::string& SkillEngine::Impl::display_path(const std::string& path) const {
  const auto it = config.display_paths.find(path);
  if (it != config.display_paths.end()) return it->second;
  // The same file written another way ("dir//s.lua", "dir/./s.lua").
  const fs::path normal = fs::path(path).lexically_normal();
  for (const auto& [real, shown] : config.display_paths) {
    if (fs::path(real).lexically_normal() == normal) return shown;
  }
  return path;
}

void SkillEngine::Impl::arm_budget() {
  budget_exhausted = false;
  used = 0;
  heap.allocated = 0;
  heap.budget = config.allocation_budget_bytes;
  heap.exhausted = false;
  heap.limit_hit = false;
  heap.refused_at[0] = '\0';
  wall_deadline = std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(config.max_cycle_wall_s));
  lua_sethook(L, budget_hook, LUA_MASKCOUNT, static_cast<int>(hook_interval(config)));
}

int SkillEngine::Impl::protected_call(int nargs, int nresults) {
  arm_budget();
  heap.in_call = true;
  const int rc = lua_pcall(L, nargs, nresults, 0);
  heap.in_call = false;
  // Outside protected calls nothing may be refused for the budget (an unprotected error would
  // panic); the flag stays for explain().
  heap.budget = 0;
  return rc;
}

std::string SkillEngine::Impl::explain(std::string msg) const {
  // A misspelt interface method (`puck_detector:nearst()`): Lua says "attempt to call a nil
  // value (method 'nearst')"; name the method meant.
  if (const std::size_t m = msg.find("(method '"); m != std::string::npos) {
    const std::size_t begin = m + 9;
    const std::size_t end = msg.find('\'', begin);
    if (end != std::string::npos) {
      static const std::vector<std::string> methods = interface_method_names();
      const std::string name = msg.substr(begin, end - begin);
      if (std::find(methods.begin(), methods.end(), name) == methods.end()) {
        if (const auto meant = core::closest_match(name, methods)) {
          msg.insert(end + 2, " (did you mean '" + *meant + "'?)");
        }
      }
    }
  }
  if (!heap.exhausted && !heap.limit_hit) return msg;
  const std::string_view oom = "not enough memory";
  std::size_t at = msg.find(oom);
  if (at == std::string::npos) return msg;
  // The skill's line, unless the message already has one ("file:12: not enough memory").
  const std::string_view before = std::string_view(msg).substr(0, at);
  const bool positioned = before.size() >= 4 && before.substr(before.size() - 2) == ": " &&
                          std::isdigit(static_cast<unsigned char>(before[before.size() - 3])) != 0;
  if (!positioned && heap.refused_at[0] != '\0') {
    const std::string located = std::string(heap.refused_at) + ": ";
    msg.insert(at, located);
    at += located.size();
  }
  if (heap.exhausted) {
    return msg.replace(at, oom.size(),
                       "allocation budget exhausted (" +
                           std::to_string(config.allocation_budget_bytes) +
                           " bytes allocated per cycle; copying big strings in a loop?)");
  }
  return msg.replace(
      at, oom.size(),
      "not enough memory (heap limit of " + std::to_string(config.memory_limit_bytes) + " bytes)");
}

void charge(lua_State* L, std::int64_t cost, int level, const char* what) {
  SkillEngine::Impl& e = SkillEngine::Impl::of(L);
  if (cost <= 0) return;
  if (cost <= e.config.instruction_budget - e.used) {
    e.used += cost;
    return;
  }
  e.used = 0;
  e.budget_exhausted = true;
  luaL_where(L, level);
  lua_pushfstring(L, "instruction budget exhausted (%I instructions per cycle; %s)",
                  static_cast<LUA_INTEGER>(e.config.instruction_budget), what);
  lua_concat(L, 2);
  lua_error(L);
}

int SkillEngine::Impl::call_entry(const char* fn, int nargs, int nresults) {
  lua_rawgeti(L, LUA_REGISTRYINDEX, engine_ref);
  lua_getfield(L, -1, fn);
  lua_remove(L, -2);
  lua_insert(L, -(nargs + 1));
  return protected_call(nargs, nresults);
}

std::vector<SkillFile> SkillEngine::Impl::scan() const {
  std::vector<SkillFile> out;
  for (const std::string& dir : config.skill_dirs) {
    std::vector<SkillFile> in_dir;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
      const fs::path& p = entry.path();
      if (p.extension() != ".lua") continue;
      // One stat() per file: this runs at every exec() with hot reload on.
      struct stat st {};
      if (::stat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
      SkillFile f;
      f.space_init = p.filename() == "init.lua";
      // (init.lua under a name no skill file has: "init@dir")
      f.name = f.space_init ? "init@" + dir : p.stem().string();
      f.path = p.string();
      f.size = static_cast<std::int64_t>(st.st_size);
      f.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 +
                   static_cast<std::int64_t>(st.st_mtim.tv_nsec);
      in_dir.push_back(std::move(f));
    }
    for (SkillFile& f : in_dir) {
      auto same = std::find_if(out.begin(), out.end(),
                               [&](const SkillFile& o) { return o.name == f.name; });
      if (same != out.end()) {
        *same = std::move(f);
      } else {
        out.push_back(std::move(f));
      }
    }
  }
  std::sort(out.begin(), out.end(),
            [](const SkillFile& a, const SkillFile& b) { return a.name < b.name; });
  return out;
}

void SkillEngine::Impl::build() {
  close();
  files = scan();
  ++loads;
  // Lua shortens chunk names over LUA_IDSIZE - 1 characters to "..." and their last
  // LUA_IDSIZE - 4 characters (luaO_chunkid); messages get the whole path back (full_paths()).
  long_paths.clear();
  for (const SkillFile& f : files) {
    const std::string& shown = display_path(f.path);
    constexpr std::size_t kKept = LUA_IDSIZE - 4;
    if (shown.size() + 1 > static_cast<std::size_t>(LUA_IDSIZE)) {
      long_paths.emplace_back("..." + shown.substr(shown.size() - kKept), shown);
    }
  }
  heap.limit = config.memory_limit_bytes;
  L = lua_newstate(limited_alloc, &heap);
  LLSF_DEMAND_MSG(L != nullptr, "cannot create a Lua state");
  heap.state = L;
  *static_cast<Impl**>(lua_getextraspace(L)) = this;
  lua_atpanic(L, panic);

  // Only the libraries the prelude needs: no io, os, package; debug stays inside the prelude.
  open_lib(L, LUA_GNAME, luaopen_base);
  open_lib(L, LUA_TABLIBNAME, luaopen_table);
  open_lib(L, LUA_STRLIBNAME, luaopen_string);
  open_lib(L, LUA_MATHLIBNAME, luaopen_math);
  open_lib(L, LUA_UTF8LIBNAME, luaopen_utf8);
  open_lib(L, LUA_DBLIBNAME, luaopen_debug);
  for (const char* name : {"dofile", "loadfile", "collectgarbage"}) {
    lua_pushnil(L);
    lua_setglobal(L, name);
  }
  // Deterministic math.random.
  lua_getglobal(L, "math");
  lua_getfield(L, -1, "randomseed");
  lua_pushinteger(L, static_cast<lua_Integer>(config.random_seed));
  lua_call(L, 1, 0);
  lua_pop(L, 1);

  // The prelude gets the natives and returns the engine's entry table.
  if (luaL_loadbufferx(L, kPrelude, std::char_traits<char>::length(kPrelude), kPreludeChunkName,
                       "t") != LUA_OK) {
    LLSF_DEMAND_MSG(false, "prelude: " + pop_message(L));
  }
  lua_newtable(L);
  const luaL_Reg natives[] = {{"now_ns", native_now_ns}, {"exhausted", native_exhausted},
                              {"log", native_log},       {"pcall", sandbox_pcall},
                              {"charge", native_charge}, {nullptr, nullptr}};
  luaL_setfuncs(L, natives, 0);
  lua_pushlstring(L, robot.name().data(), robot.name().size());
  lua_setfield(L, -2, "robot_name");
  lua_createtable(L, 0, 3);
  lua_pushstring(L, config.profile.c_str());
  lua_setfield(L, -2, "name");
  lua_pushboolean(L, config.stuck_detection ? 1 : 0);
  lua_setfield(L, -2, "stuck_detection");
  lua_pushstring(L, config.motions.c_str());
  lua_setfield(L, -2, "motions");
  lua_setfield(L, -2, "profile");
  push_interfaces(L);  // sets native.interfaces, interface_names, clock
  push_pattern_functions(L);
  lua_setfield(L, -2, "patterns");
  push_fawkes_natives(L);
  // The Fawkes layer (fawkes.lua) gets the natives too; its table goes to the prelude as
  // native.fawkes.
  if (luaL_loadbufferx(L, kFawkesLayer, std::char_traits<char>::length(kFawkesLayer),
                       kFawkesChunkName, "t") != LUA_OK) {
    LLSF_DEMAND_MSG(false, "fawkes layer: " + pop_message(L));
  }
  lua_pushvalue(L, -2);
  if (protected_call(1, 1) != LUA_OK) LLSF_DEMAND_MSG(false, "fawkes layer: " + pop_message(L));
  lua_setfield(L, -2, "fawkes");
  if (protected_call(1, 1) != LUA_OK) LLSF_DEMAND_MSG(false, "prelude: " + pop_message(L));
  engine_ref = luaL_ref(L, LUA_REGISTRYINDEX);

  // Fawkes skill spaces: a directory whose init.lua names skills with skillenv.use_skill(...)
  // has only those as skills; its other files are helper modules for require (or nothing).
  std::map<std::string, std::set<std::string>> spaces;  // directory -> the skills it names
  for (const SkillFile& f : files) {
    if (!f.space_init) continue;
    std::string read_error;
    const std::string text = read_file(f.path, read_error);
    if (!read_error.empty()) continue;  // (no space: every file is a skill)
    lua_pushlstring(L, text.data(), text.size());
    lua_pushstring(L, ("@" + display_path(f.path)).c_str());
    if (call_entry("skill_space", 2, 1) != LUA_OK || !lua_istable(L, -1)) {
      lua_settop(L, 0);
      continue;
    }
    std::set<std::string> names;
    const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, -1));
    for (lua_Integer i = 1; i <= n; ++i) {
      lua_rawgeti(L, -1, i);
      if (const char* name = lua_tostring(L, -1); name != nullptr) names.insert(name);
      lua_pop(L, 1);
    }
    lua_settop(L, 0);
    if (!names.empty()) spaces[fs::path(f.path).parent_path().lexically_normal().string()] = names;
  }
  std::vector<const SkillFile*> skill_files;
  for (const SkillFile& f : files) {
    if (f.space_init) continue;
    const auto space = spaces.find(fs::path(f.path).parent_path().lexically_normal().string());
    if (space != spaces.end() && space->second.count(f.name) == 0) continue;
    skill_files.push_back(&f);
  }

  // Handles for every skill first, so that depends_skills can be checked while files load.
  lua_createtable(L, static_cast<int>(skill_files.size()), 0);
  for (std::size_t i = 0; i < skill_files.size(); ++i) {
    lua_pushstring(L, skill_files[i]->name.c_str());
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  if (call_entry("declare_skills", 1, 0) != LUA_OK) {
    LLSF_DEMAND_MSG(false, "declare_skills: " + pop_message(L));
  }

  loading_files = true;
  for (const SkillFile* file : skill_files) {
    const SkillFile& f = *file;
    std::string load_error;
    std::string read_error;
    const std::string& shown = display_path(f.path);
    const std::string text = read_file(f.path, read_error);
    if (!read_error.empty()) {
      load_error = replace_all(read_error, f.path, shown);
    } else if (!is_identifier(f.name)) {
      load_error = shown + ": a skill's file name must be a Lua identifier";
    } else {
      lua_pushstring(L, f.name.c_str());
      lua_pushstring(L, shown.c_str());
      if (call_entry("begin_module", 2, 1) != LUA_OK) {
        load_error = pop_message(L);
      } else if (lua_isnil(L, -1)) {
        lua_pop(L, 1);  // a helper module a skill has loaded with require already
      } else {
        const std::string chunkname = "@" + shown;
        if (luaL_loadbufferx(L, text.data(), text.size(), chunkname.c_str(), "t") != LUA_OK) {
          load_error = explain(pop_message(L));
          lua_pop(L, 1);  // the module env
        } else {
          lua_insert(L, -2);                      // chunk, env
          LLSF_DEMAND(lua_setupvalue(L, -2, 1));  // _ENV = env
          if (protected_call(0, 1) != LUA_OK) {
            load_error = explain(pop_message(L));
          } else {
            // finish_module(name, what the file returned): a helper module's value for require
            lua_pushstring(L, f.name.c_str());
            lua_insert(L, -2);
            if (call_entry("finish_module", 2, 0) != LUA_OK) load_error = explain(pop_message(L));
          }
        }
      }
    }
    if (!load_error.empty()) {
      load_error = full_paths(load_error);
      lua_pushstring(L, f.name.c_str());
      lua_pushstring(L, load_error.c_str());
      if (call_entry("set_load_error", 2, 0) != LUA_OK) {
        LLSF_DEMAND_MSG(false, "set_load_error: " + pop_message(L));
      }
    }
  }
  loading_files = false;
  if (call_entry("resolve", 0, 0) != LUA_OK) LLSF_DEMAND_MSG(false, "resolve: " + pop_message(L));
  lua_settop(L, 0);
}

void SkillEngine::Impl::abort_running() {
  if (L == nullptr) return;
  if (chunk_ref != LUA_NOREF) {
    luaL_unref(L, LUA_REGISTRYINDEX, chunk_ref);
    chunk_ref = LUA_NOREF;
  }
  if (call_entry("reset_all", 0, 0) != LUA_OK) {
    const std::string msg = pop_message(L);
    if (log_sink) log_sink(LogLevel::kError, "resetting skills: " + msg);
  }
}

// ---- SkillEngine
// -----------------------------------------------------------------------------------

SkillEngine::SkillEngine(const SkillEngineConfig& cfg, RobotApi& robot)
    : impl_(std::make_unique<Impl>(cfg, robot)) {
  cfg.validate();
  impl_->build();
}

SkillEngine::~SkillEngine() = default;
SkillEngine::SkillEngine(SkillEngine&&) noexcept = default;
SkillEngine& SkillEngine::operator=(SkillEngine&&) noexcept = default;

ExecResult SkillEngine::exec(std::string_view skill_string) {
  Impl& e = *impl_;
  e.abort_running();
  if (e.config.hot_reload) {
    const std::vector<SkillFile> now = e.scan();
    const bool changed =
        now.size() != e.files.size() ||
        !std::equal(now.begin(), now.end(), e.files.begin(), [](const auto& a, const auto& b) {
          return a.path == b.path && a.mtime_ns == b.mtime_ns && a.size == b.size;
        });
    if (changed) e.build();
  }
  e.skill_string.assign(skill_string);
  e.error.clear();
  e.reason = FailReason::kNone;
  e.result.clear();
  lua_pushlstring(e.L, skill_string.data(), skill_string.size());
  if (e.call_entry("compile", 1, 2) != LUA_OK || lua_isnil(e.L, -2)) {
    e.error = lua_isstring(e.L, -1) ? lua_tostring(e.L, -1) : "cannot compile the skill string";
    lua_settop(e.L, 0);
    e.status = SkillStatus::kFailed;
    e.reason = FailReason::kBadString;
    return {false, e.error};
  }
  lua_pop(e.L, 1);
  e.chunk_ref = luaL_ref(e.L, LUA_REGISTRYINDEX);
  e.status = SkillStatus::kRunning;
  return {true, {}};
}

void SkillEngine::stop() {
  Impl& e = *impl_;
  e.abort_running();
  e.status = SkillStatus::kInactive;
  e.error.clear();
  e.reason = FailReason::kNone;
  e.result.clear();
  e.skill_string.clear();
  e.robot.stop();
}

SkillStatus SkillEngine::cycle() {
  Impl& e = *impl_;
  if (e.status != SkillStatus::kRunning) return e.status;
  lua_rawgeti(e.L, LUA_REGISTRYINDEX, e.chunk_ref);
  if (e.call_entry("run_cycle", 1, 4) != LUA_OK) {
    e.status = SkillStatus::kFailed;
    e.error = e.full_paths(e.explain(pop_message(e.L)));
    // What the prelude noted when it raised the error (an unknown skill), read without a call.
    if (any_budget_exhausted(e)) {
      e.reason = FailReason::kBudget;
    } else {
      lua_rawgeti(e.L, LUA_REGISTRYINDEX, e.engine_ref);
      lua_getfield(e.L, -1, "raised_reason");
      e.reason = lua_isstring(e.L, -1) ? reason_named(lua_tostring(e.L, -1)) : FailReason::kError;
      lua_pop(e.L, 2);
    }
  } else {
    const lua_Integer s = lua_tointeger(e.L, -4);
    e.status = static_cast<SkillStatus>(std::clamp<lua_Integer>(s, 0, 3));
    if (e.status == SkillStatus::kFailed) {
      e.error = e.full_paths(e.explain(lua_isstring(e.L, -3) ? lua_tostring(e.L, -3) : "FAILED"));
      e.reason = reason_named(lua_tostring(e.L, -1));
    }
    if (e.status != SkillStatus::kRunning) {
      const char* r = lua_tostring(e.L, -2);
      e.result = r != nullptr ? r : "";
    }
    lua_pop(e.L, 4);
  }
  if (e.status != SkillStatus::kRunning) e.abort_running();
  return e.status;
}

SkillStatus SkillEngine::status() const { return impl_->status; }
const std::string& SkillEngine::error() const { return impl_->error; }
FailReason SkillEngine::fail_reason() const {
  return impl_->status == SkillStatus::kFailed ? impl_->reason : FailReason::kNone;
}
const std::string& SkillEngine::result() const { return impl_->result; }
const std::string& SkillEngine::skill_string() const { return impl_->skill_string; }
core::SimTime SkillEngine::cycle_period() const {
  return core::SimTime::period_of_hz(impl_->config.rate_hz);
}

namespace {

// Calls skill_info(name) and hands its results (status, error, state, load_error, path,
// documentation, depends) to `fn`; false for unknown skills.
template <class Fn>
bool with_skill_info(SkillEngine::Impl& e, std::string_view skill, Fn&& fn) {
  lua_pushlstring(e.L, skill.data(), skill.size());
  if (e.call_entry("skill_info", 1, 7) != LUA_OK) {
    lua_settop(e.L, 0);
    return false;
  }
  const bool found = !lua_isnil(e.L, -7);
  if (found) {
    auto str = [&](int i) {
      const char* s = lua_tostring(e.L, i - 8);
      return std::string(s != nullptr ? s : "");
    };
    fn(static_cast<SkillStatus>(lua_tointeger(e.L, -7)), str(2), str(3), str(4), str(5), str(6),
       str(7));
  }
  lua_settop(e.L, 0);
  return found;
}

}  // namespace

SkillStatus SkillEngine::skill_status(std::string_view skill) const {
  SkillStatus out = SkillStatus::kInactive;
  with_skill_info(*impl_, skill, [&](SkillStatus s, auto&&...) { out = s; });
  return out;
}

std::string SkillEngine::skill_error(std::string_view skill) const {
  std::string out;
  with_skill_info(*impl_, skill, [&](SkillStatus, std::string err, auto&&...) { out = err; });
  return impl_->full_paths(out);
}

std::string SkillEngine::skill_state(std::string_view skill) const {
  Impl& e = *impl_;
  lua_pushlstring(e.L, skill.data(), skill.size());
  std::string out;
  if (e.call_entry("skill_state", 1, 1) == LUA_OK) {
    const char* s = lua_tostring(e.L, -1);
    if (s != nullptr) out = s;
  }
  lua_settop(e.L, 0);
  return out;
}

SkillEngine::StatePath SkillEngine::skill_state_path(std::string_view skill, bool with_via) const {
  Impl& e = *impl_;
  lua_pushlstring(e.L, skill.data(), skill.size());
  lua_pushboolean(e.L, with_via ? 1 : 0);
  StatePath out;
  // Splits `text` at `sep` into `into`.
  auto split = [](std::string_view text, char sep, std::vector<std::string>& into) {
    std::size_t b = 0;
    while (b <= text.size()) {
      const std::size_t c = std::min(text.find(sep, b), text.size());
      into.emplace_back(text.substr(b, c - b));
      b = c + 1;
    }
  };
  if (e.call_entry("skill_state", 2, 4) == LUA_OK) {
    if (const char* p = lua_tostring(e.L, -3); p != nullptr) split(p, ',', out.states);
    out.step = static_cast<std::int64_t>(lua_tointeger(e.L, -2));
    if (const char* v = lua_tostring(e.L, -1); v != nullptr && with_via) {
      split(v, '\n', out.via);
      for (std::string& s : out.via) s = e.full_paths(s);
    }
  }
  lua_settop(e.L, 0);
  return out;
}

std::string SkillEngine::skill_wait(std::string_view skill) const {
  Impl& e = *impl_;
  lua_pushlstring(e.L, skill.data(), skill.size());
  std::string out;
  if (e.call_entry("skill_wait", 1, 1) == LUA_OK) {
    if (const char* s = lua_tostring(e.L, -1); s != nullptr) out = e.full_paths(s);
  }
  lua_settop(e.L, 0);
  return out;
}

std::vector<SkillInfo> SkillEngine::skills() const {
  std::vector<SkillInfo> out;
  for (const SkillFile& f : impl_->files) {
    SkillInfo info;
    info.name = f.name;
    info.path = f.path;
    // (helper modules, files that define no skill, are not listed)
    const bool skill = with_skill_info(
        *impl_, f.name,
        [&](SkillStatus, const std::string&, const std::string&, std::string load_error,
            const std::string&, std::string doc, const std::string& deps) {
          info.load_error = std::move(load_error);
          info.documentation = std::move(doc);
          std::stringstream ss(deps);
          for (std::string d; std::getline(ss, d, ',');) {
            info.depends_skills.push_back(d);
          }
        });
    if (skill) out.push_back(std::move(info));
  }
  return out;
}

namespace {

// The field list at the top of the stack, {{name, kind, value}, ...} (fawkes.lua, field_list),
// appended to `out`; the stack stays as it was.
void read_field_list(lua_State* L, std::vector<InterfaceField>& out) {
  const auto text = [L](int index) {
    std::size_t n = 0;
    const char* s = lua_type(L, index) == LUA_TSTRING ? lua_tolstring(L, index, &n) : nullptr;
    return s != nullptr ? std::string(s, n) : std::string();
  };
  const auto add_value = [L, &text](InterfaceField& f, int index) {
    if (f.kind == InterfaceField::Kind::kSymbol || f.kind == InterfaceField::Kind::kString) {
      f.texts.push_back(text(index));
    } else if (f.kind == InterfaceField::Kind::kBool) {
      f.numbers.push_back(lua_toboolean(L, index) != 0 ? 1.0 : 0.0);
    } else {
      f.numbers.push_back(lua_tonumber(L, index));
    }
  };
  const lua_Integer nf = static_cast<lua_Integer>(lua_rawlen(L, -1));
  for (lua_Integer j = 1; j <= nf; ++j) {
    lua_rawgeti(L, -1, j);
    InterfaceField f;
    lua_rawgeti(L, -1, 1);
    f.name = text(-1);
    lua_rawgeti(L, -2, 2);
    const std::string kind = text(-1);
    f.kind = kind == "string"    ? InterfaceField::Kind::kString
             : kind == "integer" ? InterfaceField::Kind::kInteger
             : kind == "float"   ? InterfaceField::Kind::kFloat
             : kind == "bool"    ? InterfaceField::Kind::kBool
                                 : InterfaceField::Kind::kSymbol;
    lua_pop(L, 2);
    lua_rawgeti(L, -1, 3);
    if (lua_istable(L, -1)) {
      f.array = true;
      const lua_Integer ne = static_cast<lua_Integer>(lua_rawlen(L, -1));
      for (lua_Integer k = 1; k <= ne; ++k) {
        lua_rawgeti(L, -1, k);
        add_value(f, -1);
        lua_pop(L, 1);
      }
    } else {
      add_value(f, -1);
    }
    lua_pop(L, 2);  // value, field entry
    out.push_back(std::move(f));
  }
}

// Pushes {name = value (a list for an array)} of `fields`.
void push_field_values(lua_State* L, const std::vector<InterfaceField>& fields) {
  lua_createtable(L, 0, static_cast<int>(fields.size()));
  const auto push_element = [L](const InterfaceField& f, std::size_t i) {
    switch (f.kind) {
      case InterfaceField::Kind::kSymbol:
      case InterfaceField::Kind::kString:
        lua_pushlstring(L, f.texts[i].data(), f.texts[i].size());
        return;
      case InterfaceField::Kind::kBool:
        lua_pushboolean(L, f.numbers[i] != 0.0 ? 1 : 0);
        return;
      case InterfaceField::Kind::kInteger:
        lua_pushinteger(L, static_cast<lua_Integer>(f.numbers[i]));
        return;
      case InterfaceField::Kind::kFloat:
        lua_pushnumber(L, f.numbers[i]);
        return;
    }
  };
  for (const InterfaceField& f : fields) {
    const std::size_t n =
        f.kind == InterfaceField::Kind::kSymbol || f.kind == InterfaceField::Kind::kString
            ? f.texts.size()
            : f.numbers.size();
    if (f.array) {
      lua_createtable(L, static_cast<int>(n), 0);
      for (std::size_t i = 0; i < n; ++i) {
        push_element(f, i);
        lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
      }
    } else if (n > 0) {
      push_element(f, 0);
    } else {
      continue;
    }
    lua_setfield(L, -2, f.name.c_str());
  }
}

}  // namespace

std::vector<WrittenInterface> SkillEngine::written_interfaces() {
  Impl& e = *impl_;
  std::vector<WrittenInterface> out;
  if (e.L == nullptr) return out;
  // Every write counts in the blackboard's version (fawkes.lua, mark_written): the same
  // version of the same interpreter as at the last call, and nothing was written since.
  const std::int64_t version = blackboard_version();
  if (e.written_loads == e.loads && e.written_version == version) return out;
  if (e.call_entry("written_interfaces", 0, 1) != LUA_OK) {
    lua_settop(e.L, 0);
    return out;
  }
  e.written_loads = e.loads;
  e.written_version = blackboard_version();
  // {{type=, id=, serial=, fields={{name, kind, value}, ...}}, ...} (fawkes.lua, F.written)
  lua_State* L = e.L;
  const lua_Integer n = static_cast<lua_Integer>(lua_rawlen(L, -1));
  for (lua_Integer i = 1; i <= n; ++i) {
    lua_rawgeti(L, -1, i);
    WrittenInterface w;
    lua_getfield(L, -1, "type");
    w.type = lua_isstring(L, -1) ? lua_tostring(L, -1) : "";
    lua_getfield(L, -2, "id");
    w.id = lua_isstring(L, -1) ? lua_tostring(L, -1) : "";
    lua_getfield(L, -3, "serial");
    w.serial = static_cast<std::int64_t>(lua_tointeger(L, -1));
    lua_pop(L, 3);
    lua_getfield(L, -1, "fields");
    read_field_list(L, w.fields);
    lua_pop(L, 2);  // fields, entry
    out.push_back(std::move(w));
  }
  lua_settop(L, 0);
  return out;
}

std::int64_t SkillEngine::blackboard_version() const {
  const Impl& e = *impl_;
  if (e.L == nullptr) return 0;
  lua_State* L = e.L;
  lua_rawgeti(L, LUA_REGISTRYINDEX, e.engine_ref);
  lua_getfield(L, -1, "blackboard_state");
  std::int64_t v = 0;
  if (lua_istable(L, -1)) {
    lua_getfield(L, -1, "version");
    v = static_cast<std::int64_t>(lua_tointeger(L, -1));
    lua_pop(L, 1);
  }
  lua_pop(L, 2);
  return v + 1;  // (0: unknown)
}

InterfaceSnapshot SkillEngine::read_interface(std::string_view type, std::string_view id) {
  Impl& e = *impl_;
  InterfaceSnapshot out;
  if (e.L == nullptr) return out;
  lua_State* L = e.L;
  lua_pushlstring(L, type.data(), type.size());
  lua_pushlstring(L, id.data(), id.size());
  if (e.call_entry("interface_snapshot", 2, 2) != LUA_OK || !lua_istable(L, -2)) {
    out.error = lua_isstring(L, -1) ? lua_tostring(L, -1) : "cannot read the interface";
    lua_settop(L, 0);
    return out;
  }
  lua_pop(L, 1);
  out.known = true;
  lua_getfield(L, -1, "has_writer");
  out.has_writer = lua_toboolean(L, -1) != 0;
  lua_getfield(L, -2, "robot");
  out.robot_writer = lua_toboolean(L, -1) != 0;
  lua_getfield(L, -3, "written_ns");
  if (lua_isinteger(L, -1)) {
    out.written = core::SimTime::from_ns(static_cast<std::int64_t>(lua_tointeger(L, -1)));
  }
  lua_pop(L, 3);
  lua_getfield(L, -1, "fields");
  read_field_list(L, out.fields);
  lua_settop(L, 0);
  return out;
}

std::string SkillEngine::write_interface(std::string_view type, std::string_view id,
                                         const std::vector<InterfaceField>& fields) {
  Impl& e = *impl_;
  if (e.L == nullptr) return "the skill engine has no interpreter";
  lua_State* L = e.L;
  lua_pushlstring(L, type.data(), type.size());
  lua_pushlstring(L, id.data(), id.size());
  push_field_values(L, fields);
  std::string error;
  if (e.call_entry("interface_set", 3, 0) != LUA_OK) error = pop_message(L);
  lua_settop(L, 0);
  return error;
}

std::int64_t SkillEngine::send_interface_message(std::string_view type, std::string_view id,
                                                 std::string_view message,
                                                 const std::vector<InterfaceField>& fields,
                                                 std::string& error) {
  Impl& e = *impl_;
  if (e.L == nullptr) {
    error = "the skill engine has no interpreter";
    return 0;
  }
  lua_State* L = e.L;
  lua_pushlstring(L, type.data(), type.size());
  lua_pushlstring(L, id.data(), id.size());
  lua_pushlstring(L, message.data(), message.size());
  push_field_values(L, fields);
  std::int64_t msgid = 0;
  if (e.call_entry("interface_send", 4, 1) != LUA_OK) {
    error = pop_message(L);
  } else {
    msgid = static_cast<std::int64_t>(lua_tointeger(L, -1));
  }
  lua_settop(L, 0);
  return msgid;
}

std::vector<std::string> SkillEngine::load_errors() const {
  std::vector<std::string> out;
  for (const SkillInfo& s : skills()) {
    if (!s.load_error.empty()) out.push_back(s.name + ": " + s.load_error);
  }
  return out;
}

void SkillEngine::reload() {
  impl_->abort_running();
  if (impl_->status == SkillStatus::kRunning) impl_->status = SkillStatus::kInactive;
  impl_->build();
}

int SkillEngine::load_count() const { return impl_->loads; }

void SkillEngine::set_log_sink(std::function<void(LogLevel, std::string_view)> sink) {
  Impl& e = *impl_;
  e.log_sink = std::move(sink);
  if (!e.log_sink) return;
  // What the files logged while they loaded (before there was a sink).
  std::vector<std::pair<LogLevel, std::string>> pending;
  pending.swap(e.pending_log);
  for (const auto& [level, text] : pending) e.log_sink(level, text);
  if (e.pending_dropped > 0) {
    e.log_sink(LogLevel::kWarn, std::to_string(e.pending_dropped) +
                                    " more lines logged while the skill files loaded were dropped");
    e.pending_dropped = 0;
  }
}

}  // namespace llsf::lua
