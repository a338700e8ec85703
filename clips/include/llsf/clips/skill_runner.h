// SPDX-License-Identifier: MIT
// SkillRunner: what an agent needs from a skill engine (Fawkes' SkillerInterface, reduced). The
// sim module adapts its Lua SkillEngine to it; tests use FakeSkillRunner (llsf/clips/testing.h).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace llsf::clips {

/// Status of the skill string a runner executes (Fawkes' skill fact values; IDLE = S_INACTIVE).
enum class SkillStatus : std::uint8_t { kIdle, kRunning, kFinal, kFailed };

/// "IDLE", "RUNNING", "FINAL", "FAILED" (the symbols of the `skill` fact).
const char* to_string(SkillStatus status);

/// One robot's skill executor. Only one skill string runs at a time: exec() replaces the current
/// one. The agent host polls status() once per agent cycle and never calls it concurrently.
class SkillRunner {
 public:
  virtual ~SkillRunner() = default;
  /// Starts executing a Lua skill string such as `drive_to{place="M1"}`, aborting the current
  /// one. Errors (unknown skill, syntax) show up as status() FAILED with error().
  virtual void exec(std::string_view skill_string) = 0;
  /// Aborts the current skill string (status becomes IDLE).
  virtual void stop() = 0;
  /// Status of the current (or last) skill string.
  virtual SkillStatus status() const = 0;
  /// Error text of a FAILED string (empty otherwise).
  virtual std::string error() const = 0;
  /// What the skills reported when the string ended (the Lua engine's result(), e.g. "DONE");
  /// empty while running or if none did.
  virtual std::string result() const { return {}; }
  /// The skill string being (or last) executed; the host uses it to tell whether the runner
  /// still works on the string this agent sent.
  virtual std::string skill_string() const = 0;
};

}  // namespace llsf::clips
