// SPDX-License-Identifier: MIT
// Internals of SkillEngine shared by the engine (skill_engine.cpp) and the robot interface
// bindings (interfaces.cpp). Lua is the C library: errors are longjmps, so no C++ object with a
// destructor may live in a frame a Lua error can unwind (values read from RobotApi are cached in
// members instead).
#pragma once

#include <lua.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "llsf/lua/skill_engine.h"

namespace llsf::lua {

/// The text embedded from src/prelude.lua (generated prelude.cpp).
extern const char* const kPrelude;

/// Heap accounting of one interpreter.
struct LuaHeap {
  std::int64_t used = 0;
  std::int64_t limit = 0;
};

/// One skill file as last loaded (for hot reload).
struct SkillFile {
  std::string name;
  std::string path;
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
  std::vector<SkillFile> files;
  int loads = 0;

  SkillStatus status = SkillStatus::kInactive;
  std::string error;
  std::string result;  // fsm.result of the string's skills when it ended
  std::string skill_string;
  std::function<void(LogLevel, std::string_view)> log_sink;

  // Caches for the bindings (see the file comment).
  NavState nav;
  LightReading light;
  std::string cpp_error;

  /// The engine that owns `L` (stored in the state's extra space).
  static Impl& of(lua_State* L) { return **static_cast<Impl**>(lua_getextraspace(L)); }

  /// Scans the skill directories (sorted by name; later directories win).
  std::vector<SkillFile> scan() const;
  /// Closes the interpreter and builds a new one with every skill loaded.
  void build();
  void close();
  /// Starts a fresh instruction budget for the next protected call.
  void arm_budget();
  /// Calls the entry `fn` of the prelude with `nargs` arguments already pushed, protected and
  /// under a fresh budget; returns the Lua status (the error message is left on the stack).
  int call_entry(const char* fn, int nargs, int nresults);
  /// Aborts the running skill string: resets every skill (exit hooks run).
  void abort_running();
};

/// Registers the robot interfaces: pushes a table type name -> interface object, and sets the
/// globals the prelude reads from `native` (clock, interface names).
void push_interfaces(lua_State* L);

}  // namespace llsf::lua
