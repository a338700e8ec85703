// SPDX-License-Identifier: MIT
#include "sandbox.h"

#include <algorithm>
#include <string>

#include "environment.h"

namespace llsf::clips::detail {

namespace {

// CLIPS 6.30's functions (Debian's build; those it lacks are skipped) that reach outside the
// environment, block on the terminal, end the process or pull the host's constructs away.
constexpr std::string_view kFunctions[] = {
    // files and I/O routers (read/readline/... would wait on the terminal's stdin)
    "open", "close", "read", "readline", "read-number", "get-char", "remove", "rename",
    // code and facts from or to files
    "load", "load*", "bload", "batch", "batch*", "save", "bsave", "save-facts", "load-facts",
    "save-instances", "load-instances", "bsave-instances", "bload-instances", "restore-instances",
    "dribble-on", "dribble-off",
    // the text-processing files (fetch reads a file)
    "fetch", "toss", "print-region", "get-region",
    // the process and the terminal
    "system", "exit", "edit",
    // the whole environment and the host's constructs
    "clear", "reset", "undeftemplate", "undefrule", "undeffacts", "undefglobal", "undeffunction",
    "undefgeneric", "undefmethod", "undefclass", "undefinstances", "undefmessage-handler"};

}  // namespace

std::span<const std::string_view> sandboxed_functions() { return kFunctions; }

void install_sandbox(Environment& env, std::span<const std::string_view> allowed) {
  for (const std::string_view name : kFunctions) {
    if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
    env.forbid_function(std::string(name),
                        "not available in agents (the sandbox: no files, I/O, process control or "
                        "removal of constructs; docs/security.md)");
  }
}

}  // namespace llsf::clips::detail
