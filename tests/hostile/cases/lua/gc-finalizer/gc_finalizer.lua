-- SPDX-License-Identifier: MIT
-- Hostile skill: a __gc finalizer (would run outside the budget)
name = "gc_finalizer"
documentation = "hostile input: a __gc finalizer (would run outside the budget)"
function execute()
  setmetatable({}, {__gc = function() while true do end end})
  return S_FINAL
end
