// SPDX-License-Identifier: MIT
#include "llsf/core/text.h"

#include <algorithm>
#include <vector>

namespace llsf::core {

int edit_distance(std::string_view a, std::string_view b) {
  std::vector<int> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diag = row[0];
    row[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::optional<std::string> closest_match(std::string_view name,
                                         std::span<const std::string> candidates) {
  const std::string* best = nullptr;
  int best_d = std::max(1, static_cast<int>(name.size()) / 3) + 1;
  for (const std::string& c : candidates) {
    if (const int d = edit_distance(name, c); d < best_d) {
      best = &c;
      best_d = d;
    }
  }
  if (best == nullptr) return std::nullopt;
  return *best;
}

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace llsf::core
