-- SPDX-License-Identifier: MIT
-- Hostile skill: string.format with a 99999-digit width
name = "format_huge"
documentation = "hostile input: string.format with a 99999-digit width"
function execute()
  local s = string.format("%099999d", 1)
  return S_FINAL
end
