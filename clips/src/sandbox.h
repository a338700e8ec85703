// SPDX-License-Identifier: MIT
// The agents' sandbox (docs/security.md): the CLIPS functions an agent may not call.
#pragma once

#include <span>
#include <string_view>

namespace llsf::clips::detail {

class Environment;

/// The functions the sandbox takes away: files and I/O routers, loading and saving code or
/// facts, dribble, system and exit, clear/reset and the removal of constructs.
std::span<const std::string_view> sandboxed_functions();

/// Makes every sandboxed function unavailable in `env` (Environment::forbid_function), except
/// those in `allowed` (a Fawkes-style agent's (reset), which the host replaces by its own).
void install_sandbox(Environment& env, std::span<const std::string_view> allowed = {});

}  // namespace llsf::clips::detail
