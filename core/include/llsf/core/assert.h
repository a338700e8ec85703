// SPDX-License-Identifier: MIT
// Checks for programmer bugs: LLSF_DEMAND is always on, LLSF_ASSERT only in debug/asserting builds.
#pragma once

#include <stdexcept>
#include <string>

namespace llsf::core {

/// Thrown when an LLSF_DEMAND/LLSF_ASSERT condition fails: a bug in llsfsim, not bad user input.
class AssertionError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] void demand_failed(const char* condition, const char* file, int line,
                                const std::string& message);
}  // namespace detail

}  // namespace llsf::core

/// Always-on check of an invariant; throws llsf::core::AssertionError naming file and line.
#define LLSF_DEMAND(cond)        \
  ((cond) ? static_cast<void>(0) \
          : ::llsf::core::detail::demand_failed(#cond, __FILE__, __LINE__, std::string()))

/// LLSF_DEMAND with an explanatory message (any expression convertible to std::string).
#define LLSF_DEMAND_MSG(cond, msg) \
  ((cond) ? static_cast<void>(0)   \
          : ::llsf::core::detail::demand_failed(#cond, __FILE__, __LINE__, (msg)))

#if !defined(NDEBUG) || defined(LLSF_ENABLE_ASSERTS)
/// Debug-only check (on without NDEBUG or with LLSF_ENABLE_ASSERTS); free in Release builds.
#define LLSF_ASSERT(cond) LLSF_DEMAND(cond)
#else
#define LLSF_ASSERT(cond) static_cast<void>(0)
#endif
