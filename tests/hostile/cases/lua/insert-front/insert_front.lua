-- SPDX-License-Identifier: MIT
-- Hostile skill: table.insert at the front of a long list, in a loop
name = "insert_front"
documentation = "hostile input: table.insert at the front of a long list, in a loop"
function execute()
  local t = {}
  for i = 1, 100000 do t[i] = i end
  for i = 1, 1000000 do table.insert(t, 1, i) end
  return S_FINAL
end
