-- SPDX-License-Identifier: MIT
-- Hostile skill: an endless loop
name = "endless"
documentation = "hostile input: an endless loop"
function execute()
  local n = 0
  while true do n = n + 1 end
  return S_FINAL
end
