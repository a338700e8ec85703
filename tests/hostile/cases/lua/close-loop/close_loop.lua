-- SPDX-License-Identifier: MIT
-- Hostile skill: a to-be-closed variable whose __close loops for ever during an error
name = "close_loop"
documentation = "hostile input: a to-be-closed variable whose __close loops for ever during an error"
function execute()
  local guard <close> = setmetatable({}, {__close = function() while true do end end})
  error("boom")
  return S_FINAL
end
