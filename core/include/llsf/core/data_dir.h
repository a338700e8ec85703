// SPDX-License-Identifier: MIT
// Where llsfsim's run-time data lives: an installed prefix, the source tree, or $LLSF_DATA_DIR.
#pragma once

#include <string>

namespace llsf::core {

/// The directory of llsfsim's run-time data (clips/agents, lua/skills, scenarios, exercises,
/// experiments, config, viewer/dist; the same layout in every case): $LLSF_DATA_DIR if set and not
/// empty; else <dir of the running executable>/../share/llsfsim if that exists (an installed
/// llsfsim); else the source tree this library was built from (a build-tree run). Looked up on
/// every call; reads the environment, so not to be called while another thread sets it.
std::string data_dir();

/// The source tree this library was built from (the last fallback of data_dir()).
std::string source_data_dir();

}  // namespace llsf::core
