-- SPDX-License-Identifier: MIT
-- Hostile skill: a plain search whose every candidate compares a million bytes
name = "find_plain"
documentation = "hostile input: a plain search whose every candidate compares a million bytes"
function execute()
  local s = string.rep("a", 3000000)
  s:find(string.rep("a", 1000000) .. "b", 1, true)
  return S_FINAL
end
