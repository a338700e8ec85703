// SPDX-License-Identifier: MIT
// Small text helpers: edit distance and the "did you mean" candidate for messages; escaping
// text for HTML, SVG and XML.
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

/// `text` with &, <, > and " replaced by their entities (&amp; &lt; &gt; &quot;): safe in HTML,
/// SVG and XML element text and in double-quoted attribute values. The one escaping of the
/// report page and `field-map`'s SVG.
std::string xml_escape(std::string_view text);

}  // namespace llsf::core
