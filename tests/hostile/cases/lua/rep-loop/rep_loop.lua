-- SPDX-License-Identifier: MIT
-- Hostile skill: 10 MB strings built in a loop (each call fits, the loop does not)
name = "rep_loop"
documentation = "hostile input: 10 MB strings built in a loop (each call fits, the loop does not)"
function execute()
  for i = 1, 1000000 do local s = string.rep("x", 10000000) end
  return S_FINAL
end
