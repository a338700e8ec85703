// SPDX-License-Identifier: MIT
// documented_params (skill_doc.h): the `@param` lines of a skill's documentation.
#include "llsf/lua/skill_doc.h"

#include <cctype>

namespace llsf::lua {

std::vector<std::string> documented_params(std::string_view doc) {
  std::vector<std::string> out;
  for (std::size_t at = doc.find("@param"); at != std::string_view::npos;
       at = doc.find("@param", at + 1)) {
    std::size_t i = at + 6;
    for (;;) {
      while (i < doc.size() && (doc[i] == ' ' || doc[i] == '\t')) ++i;
      std::size_t e = i;
      while (e < doc.size() &&
             (std::isalnum(static_cast<unsigned char>(doc[e])) != 0 || doc[e] == '_'))
        ++e;
      if (e == i) break;
      out.emplace_back(doc.substr(i, e - i));
      i = e;
      if (i < doc.size() && doc[i] == ',') {
        ++i;
        continue;
      }
      break;
    }
  }
  return out;
}

}  // namespace llsf::lua
