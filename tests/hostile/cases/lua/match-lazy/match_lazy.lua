-- SPDX-License-Identifier: MIT
-- Hostile skill: string.match with a chain of lazy items
name = "match_lazy"
documentation = "hostile input: string.match with a chain of lazy items"
function execute()
  local s = string.rep("a", 30000)
  s:match(".-.-.-b")
  return S_FINAL
end
