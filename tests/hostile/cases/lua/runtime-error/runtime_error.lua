-- SPDX-License-Identifier: MIT
-- Hostile skill: indexing nil
name = "runtime_error"
documentation = "hostile input: indexing nil"
function execute()
  local t = nil
  local x = t.field
  return S_FINAL
end
