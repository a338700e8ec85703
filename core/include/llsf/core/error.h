// SPDX-License-Identifier: MIT
// Errors for bad user input (config files, scenario files, command lines).
#pragma once

#include <stdexcept>
#include <string>

namespace llsf::core {

/// An error of the user's, not of llsfsim: bad input (a file, a path, a port, a command line) or
/// an environment that refuses it (a file that cannot be read or written, a port in use). The
/// llsfsim command exits with 2 for these; any other exception is a bug (exit code 3).
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad user input in a configuration: the message names the file, line and field.
class ConfigError : public UserError {
 public:
  using UserError::UserError;
};

}  // namespace llsf::core
