// SPDX-License-Identifier: MIT
// Running llsfsim in-process for the app tests: exit code and captured output.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "llsf/app/cli.h"

namespace llsf::test {

struct Run {
  int code = -1;
  std::string out;
  std::string err;
};

/// `llsfsim ARGS...` in-process.
inline Run llsfsim(std::vector<std::string> args) {
  args.insert(args.begin(), "llsfsim");
  std::ostringstream out;
  std::ostringstream err;
  Run r;
  r.code = llsf::app::run(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

inline bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace llsf::test
