-- SPDX-License-Identifier: MIT
-- Hostile skill: dumping bytecode
name = "string_dump"
documentation = "hostile input: dumping bytecode"
function execute()
  local b = string.dump(function() end)
  return S_FINAL
end
