-- SPDX-License-Identifier: MIT
-- Hostile skill: string.rep of 2^40 copies with a separator
name = "rep_huge"
documentation = "hostile input: string.rep of 2^40 copies with a separator"
function execute()
  local s = string.rep("x", 2^40, "y")
  return S_FINAL
end
