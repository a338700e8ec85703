-- SPDX-License-Identifier: MIT
-- Hostile skill: a pattern nesting 300 optional items
name = "pattern_deep"
documentation = "hostile input: a pattern nesting 300 optional items"
function execute()
  string.find(string.rep("x", 300), string.rep("x?", 300))
  return S_FINAL
end
