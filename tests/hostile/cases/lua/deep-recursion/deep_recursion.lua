-- SPDX-License-Identifier: MIT
-- Hostile skill: unbounded recursion
name = "deep_recursion"
documentation = "hostile input: unbounded recursion"
function execute()
  local function f(n) return 1 + f(n + 1) end
  f(1)
  return S_FINAL
end
