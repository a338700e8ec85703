// SPDX-License-Identifier: MIT
#include "llsf/core/assert.h"

namespace llsf::core::detail {

void demand_failed(const char* condition, const char* file, int line, const std::string& message) {
  std::string what =
      std::string(file) + ":" + std::to_string(line) + ": internal check failed: " + condition;
  if (!message.empty()) what += " (" + message + ")";
  throw AssertionError(what);
}

}  // namespace llsf::core::detail
