// SPDX-License-Identifier: MIT
// Checks of command-line values with messages a user can read (CLI11's PositiveNumber prints its
// range up to the largest double, 309 digits; an unsigned option takes `-3` as 2^64 - 3).
#pragma once

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdlib>
#include <string>

namespace llsf::app {

/// A number > 0 (a count, a factor, seconds).
inline const CLI::Validator kPositive(
    [](std::string& v) -> std::string {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0') return "'" + v + "' is not a number";
      if (!(x > 0.0)) return "must be greater than 0, not " + v;
      return "";
    },
    "POSITIVE");

/// A number >= 0.
inline const CLI::Validator kNonNegative(
    [](std::string& v) -> std::string {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0') return "'" + v + "' is not a number";
      if (!(x >= 0.0)) return "must be 0 or more, not " + v;
      return "";
    },
    "NONNEGATIVE");

/// A seed: a whole number from 0 to 2^64 - 1, written in decimal digits only.
inline const CLI::Validator kSeed(
    [](std::string& v) -> std::string {
      const std::string why =
          "a seed is a whole number from 0 to 18446744073709551615, not '" + v + "'";
      if (v.empty() || v.find_first_not_of("0123456789") != std::string::npos) return why;
      errno = 0;
      (void)std::strtoull(v.c_str(), nullptr, 10);
      if (errno == ERANGE) return why;
      return "";
    },
    "SEED");

}  // namespace llsf::app
