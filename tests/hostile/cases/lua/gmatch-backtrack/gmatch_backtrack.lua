-- SPDX-License-Identifier: MIT
-- Hostile skill: string.gmatch with a backtracking pattern
name = "gmatch_backtrack"
documentation = "hostile input: string.gmatch with a backtracking pattern"
function execute()
  for w in string.gmatch(string.rep("a", 30000), "a*a*b") do end
  return S_FINAL
end
