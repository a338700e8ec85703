-- SPDX-License-Identifier: MIT
-- Hostile skill: table.unpack over 2^40 elements
name = "unpack_huge"
documentation = "hostile input: table.unpack over 2^40 elements"
function execute()
  local a = table.unpack({}, 1, 2^40)
  return S_FINAL
end
