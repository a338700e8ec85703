// SPDX-License-Identifier: MIT
// Errors for bad user input (config files, scenario files, command lines).
#pragma once

#include <stdexcept>
#include <string>

namespace llsf::core {

/// Bad user input in a configuration: the message names the file, line and field.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace llsf::core
