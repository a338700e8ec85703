-- SPDX-License-Identifier: MIT
-- Hostile skill: rawset into the shared table library
name = "tamper_rawset"
documentation = "hostile input: rawset into the shared table library"
function execute()
  rawset(table, "concat", function() return "" end)
  return S_FINAL
end
