// SPDX-License-Identifier: MIT
// What a skill's documentation declares (docs/skills.md, "documentation"): its arguments.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace llsf::lua {

/// The argument names `documentation` declares, one `@param NAME[, NAME...] text` per line
/// (SkillInfo::documentation), in order; empty for a skill without `@param` lines.
std::vector<std::string> documented_params(std::string_view documentation);

}  // namespace llsf::lua
