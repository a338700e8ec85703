-- SPDX-License-Identifier: MIT
-- Hostile skill: string.rep of an empty string 2^50 times (Lua's own loops for ever): must work, at once
name = "rep_empty"
documentation = "hostile input: string.rep of an empty string 2^50 times (Lua's own loops for ever): must work, at once"
function execute()
  local s = string.rep("", 2^50) .. string.rep("", 2^50, "")
  assert(s == "")
  return S_FINAL
end
