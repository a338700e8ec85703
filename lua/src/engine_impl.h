// SPDX-License-Identifier: MIT
// Internals of SkillEngine shared by the engine (skill_engine.cpp) and the robot interface
// bindings (interfaces.cpp). Lua is the C library: errors are longjmps, so no C++ object with a
// destructor may live in a frame a Lua error can unwind (values read from RobotApi are cached in
// members instead).
#pragma once

#include <lua.hpp>

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "llsf/lua/skill_engine.h"

namespace llsf::lua {

/// The text embedded from src/prelude.lua (generated prelude.cpp).
extern const char* const kPrelude;
/// The text embedded from src/fawkes.lua, the Fawkes compatibility layer (generated prelude.cpp).
extern const char* const kFawkesLayer;

/// Heap accounting of one interpreter.
struct LuaHeap {
  std::int64_t used = 0;
  std::int64_t limit = 0;
  /// Bytes allocated since the budget was last armed, and how many may be (allocation budget).
  std::int64_t allocated = 0;
  std::int64_t budget = 0;
  /// Set when an allocation was refused for the allocation budget; from then on the running code
  /// gets kAllocationGrace more bytes (to unwind and report), then nothing.
  bool exhausted = false;
  /// Set when an allocation was refused for the heap limit.
  bool limit_hit = false;
  /// The interpreter, and whether a protected call runs in it: only then is a refusal located.
  lua_State* state = nullptr;
  bool in_call = false;
  /// "file:line" of the skill code running when an allocation was last refused (the innermost
  /// frame of a skill file); empty if none. Memory errors carry no position of their own.
  char refused_at[256] = {};
};

/// Bytes an interpreter may still allocate after its allocation budget ran out (error messages,
/// the prelude's bookkeeping while the failure unwinds).
inline constexpr std::int64_t kAllocationGrace = 1 << 20;
/// The count hook runs every kHookInterval VM instructions (or every instruction_budget
/// instructions if that is smaller) and adds them to Impl::used.
inline constexpr std::int64_t kHookInterval = 1000;

/// Lines kept while the files load without a log sink (SkillEngine::Impl::pending_log).
inline constexpr std::size_t kMaxPendingLog = 200;

/// A Fawkes navgraph as read from its YAML file (fawkes_natives.cpp), before it goes to Lua.
struct NavgraphNode {
  std::string name;
  double x = 0.0;
  double y = 0.0;
  bool unconnected = false;  ///< tagged !unconnected
  std::vector<std::pair<std::string, std::string>> properties;
};
struct NavgraphEdge {
  std::string from;
  std::string to;
  bool directed = false;  ///< tagged !dir
};
struct NavgraphData {
  std::string name;
  std::string root;
  std::vector<NavgraphNode> nodes;
  std::vector<NavgraphEdge> edges;
};

/// One skill file as last loaded (for hot reload).
struct SkillFile {
  std::string name;
  std::string path;
  /// The directory's init.lua (a Fawkes skill space naming its skills), not a skill.
  bool space_init = false;
  std::int64_t mtime_ns = 0;
  std::int64_t size = 0;
};

struct SkillEngine::Impl {
  Impl(const SkillEngineConfig& cfg, RobotApi& robot_api);
  ~Impl();

  SkillEngineConfig config;
  RobotApi& robot;
  lua_State* L = nullptr;
  LuaHeap heap;
  int engine_ref = LUA_NOREF;  // the prelude's entry table
  int chunk_ref = LUA_NOREF;   // the compiled skill string
  bool budget_exhausted = false;
  /// Instructions used since the budget was armed: VM instructions counted by the hook plus the
  /// work library functions charge (charge()).
  std::int64_t used = 0;
  /// When the armed cycle's wall-time budget ends (config.max_cycle_wall_s).
  std::chrono::steady_clock::time_point wall_deadline;
  std::vector<SkillFile> files;
  /// (shortened, whole) shown path of every skill file whose path Lua shortens.
  std::vector<std::pair<std::string, std::string>> long_paths;
  int loads = 0;
  // SkillEngine::written_interfaces: the interpreter (loads) and blackboard version at its last
  // call (-1: none yet).
  int written_loads = -1;
  std::int64_t written_version = -1;

  SkillStatus status = SkillStatus::kInactive;
  std::string error;
  FailReason reason = FailReason::kNone;
  std::string result;  // fsm.result of the string's skills when it ended
  std::string skill_string;
  std::function<void(LogLevel, std::string_view)> log_sink;
  /// Lines logged while the files load with no sink set yet (a skill file's top-level print):
  /// delivered by set_log_sink(), at most kMaxPendingLog of them.
  std::vector<std::pair<LogLevel, std::string>> pending_log;
  int pending_dropped = 0;
  bool loading_files = false;

  // Caches for the bindings (see the file comment).
  NavState nav;
  LightReading light;
  std::string cpp_error;
  std::string module_text;  // the module `require` read last, and its shown path
  std::string module_path;
  bool module_in_skill_dir = false;
  NavgraphData navgraph;  // the navgraph file read last

  /// The engine that owns `L` (stored in the state's extra space).
  static Impl& of(lua_State* L) { return **static_cast<Impl**>(lua_getextraspace(L)); }

  /// The path messages show for the skill file `path` (config.display_paths, else `path`).
  const std::string& display_path(const std::string& path) const;
  /// `text` with every shortened path of a skill file ("...tail", as Lua writes chunk names
  /// over LUA_IDSIZE) written out in full.
  std::string full_paths(std::string text) const;
  /// Scans the skill directories (sorted by name; later directories win).
  std::vector<SkillFile> scan() const;
  /// Closes the interpreter and builds a new one with every skill loaded.
  void build();
  void close();
  /// Starts fresh budgets (instructions, allocation) for the next protected call.
  void arm_budget();
  /// lua_pcall under fresh budgets; the allocation budget applies only inside.
  int protected_call(int nargs, int nresults);
  /// Calls the entry `fn` of the prelude with `nargs` arguments already pushed, protected and
  /// under a fresh budget; returns the Lua status (the error message is left on the stack).
  int call_entry(const char* fn, int nargs, int nresults);
  /// Aborts the running skill string: resets every skill (exit hooks run).
  void abort_running();
  /// "not enough memory" in `msg` explained: the allocation budget that ran out, or the heap limit
  /// with its figure (for the last protected call).
  std::string explain(std::string msg) const;
};

/// Charges `cost` instructions of work done by a library function (`what`, e.g. "table.move of
/// 10 elements") to the running code's instruction budget; raises the budget error at the Lua
/// code `level` levels up (1: the caller of the C function running) once it is exhausted.
void charge(lua_State* L, std::int64_t cost, int level, const char* what);

/// Pushes a table with the bounded string functions rep, find, match, gmatch, gsub
/// (patterns.cpp).
void push_pattern_functions(lua_State* L);

/// Registers the robot interfaces: pushes a table type name -> interface object, and sets the
/// globals the prelude reads from `native` (clock, interface names).
void push_interfaces(lua_State* L);
/// Sets the natives of the Fawkes layer in the table at -1: read_module, navgraph (reads files
/// of the configured directories) and fawkes_config (path -> value text).
void push_fawkes_natives(lua_State* L);
/// The method names of every interface type (pose:get, puck_detector:nearest, ...), each once:
/// for the "did you mean" of a misspelt method.
std::vector<std::string> interface_method_names();

}  // namespace llsf::lua
