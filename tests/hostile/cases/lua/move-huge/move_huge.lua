-- SPDX-License-Identifier: MIT
-- Hostile skill: table.move over 2^50 elements
name = "move_huge"
documentation = "hostile input: table.move over 2^50 elements"
function execute()
  table.move({}, 1, 2^50, 2)
  return S_FINAL
end
