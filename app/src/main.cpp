// SPDX-License-Identifier: MIT
// llsfsim: the command-line front end (see `llsfsim --help` and docs/llsfsim.md).
#include <iostream>
#include <string>
#include <vector>

#include "llsf/app/cli.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  return llsf::app::run(args, std::cout, std::cerr);
}
