// SPDX-License-Identifier: MIT
// Mistakes in agent code that CLIPS loads without a word but that make a rule misbehave, found
// by reading the source (docs/clips.md, "Where the (time) pattern goes"): a rule condition that
// reads the clock where CLIPS never evaluates it again as time passes.
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace llsf::clips {

/// One finding in a source text: its 1-based line and what is wrong, for people.
struct SourceWarning {
  int line = 0;
  std::string message;
};

/// Finds rule conditions that read the time (`(now)`, `(now-sec-usec)`, or a deffunction that
/// calls one) where CLIPS
/// does not evaluate them again when time passes: a `(test ...)` with no `(time ...)` pattern
/// before it (a test is evaluated when the facts matched before it change), and a slot
/// constraint of a fact pattern (`(timer (until ?u&:(< ?u (now))))`: tested when that fact
/// changes) unless it joins a variable of an earlier pattern after a `(time ...)` pattern. Such a
/// rule fires late or never. Files are scanned in load order: a deffunction that reads the time
/// counts in the files after its own.
class TimeReadCheck {
 public:
  /// The findings in one file's code, in line order.
  std::vector<SourceWarning> scan(std::string_view code);

 private:
  /// The host's clock functions, then the deffunctions that call one.
  std::set<std::string, std::less<>> time_functions_ = {"now", "now-sec-usec"};
};

}  // namespace llsf::clips
