-- SPDX-License-Identifier: MIT
-- Hostile skill: a 16 MB string concatenated with itself a million times
name = "copy_loop"
documentation = "hostile input: a 16 MB string concatenated with itself a million times"
function execute()
  local s = string.rep("x", 16 << 20)
  for i = 1, 1000000 do local t = s .. s end
  return S_FINAL
end
