-- SPDX-License-Identifier: MIT
-- Hostile skill: coroutines (not in the sandbox)
name = "coroutine_abuse"
documentation = "hostile input: coroutines (not in the sandbox)"
function execute()
  local co = coroutine.wrap(function() while true do coroutine.yield() end end)
  return S_FINAL
end
