-- SPDX-License-Identifier: MIT
-- Hostile skill: string.gsub with a backtracking pattern
name = "gsub_backtrack"
documentation = "hostile input: string.gsub with a backtracking pattern"
function execute()
  local s = string.rep("a", 30000)
  s:gsub("a*a*a*b", "")
  return S_FINAL
end
