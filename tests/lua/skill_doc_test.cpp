// SPDX-License-Identifier: MIT
// The arguments a skill's documentation declares (skill_doc.h), as `llsfsim check` compares a
// skill call's arguments with them.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "llsf/lua/skill_doc.h"

using llsf::lua::documented_params;
using Names = std::vector<std::string>;

TEST_CASE("documented_params: one @param line per argument, several names on one line") {
  CHECK(documented_params("Drive to a place.\n"
                          "@param place  name of the place (string)\n"
                          "@param\tx, y, ori  a pose instead (m, rad)\n"
                          "@param timeout_s seconds at most\n") ==
        Names{"place", "x", "y", "ori", "timeout_s"});
  CHECK(documented_params("Waits. No arguments.").empty());
  CHECK(documented_params("@param").empty());           // no name
  CHECK(documented_params("@param -x text").empty());   // not a name
  CHECK(documented_params("@param a,") == Names{"a"});  // a comma with no name after it
}
