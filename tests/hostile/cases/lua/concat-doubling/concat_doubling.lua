-- SPDX-License-Identifier: MIT
-- Hostile skill: a string that doubles until memory runs out
name = "concat_doubling"
documentation = "hostile input: a string that doubles until memory runs out"
function execute()
  local s = "x"
  while true do s = s .. s end
  return S_FINAL
end
