-- SPDX-License-Identifier: MIT
-- Hostile skill: an endless loop whose budget error a pcall tries to swallow
name = "pcall_swallow"
documentation = "hostile input: an endless loop whose budget error a pcall tries to swallow"
function execute()
  while true do pcall(function() while true do end end) end
  return S_FINAL
end
