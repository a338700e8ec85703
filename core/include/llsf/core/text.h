// SPDX-License-Identifier: MIT
// Small text helpers for messages: edit distance and the "did you mean" candidate.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace llsf::core {

/// Levenshtein distance (insert, delete, substitute one character).
int edit_distance(std::string_view a, std::string_view b);

/// The candidate closest to `name` if it is within a third of the name's length (a likely
/// typo), else nullopt.
std::optional<std::string> closest_match(std::string_view name,
                                         std::span<const std::string> candidates);

}  // namespace llsf::core
