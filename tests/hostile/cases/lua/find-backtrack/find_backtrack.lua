-- SPDX-License-Identifier: MIT
-- Hostile skill: string.find with five greedy items on 30000 characters
name = "find_backtrack"
documentation = "hostile input: string.find with five greedy items on 30000 characters"
function execute()
  string.find(string.rep("a", 30000), "a*a*a*a*a*b")
  return S_FINAL
end
