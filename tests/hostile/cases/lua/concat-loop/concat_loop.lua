-- SPDX-License-Identifier: MIT
-- Hostile skill: table.concat of 100000 elements, a million times
name = "concat_loop"
documentation = "hostile input: table.concat of 100000 elements, a million times"
function execute()
  local t = {}
  for i = 1, 100000 do t[i] = "" end
  for i = 1, 1000000 do local s = table.concat(t) end
  return S_FINAL
end
