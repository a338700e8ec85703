-- SPDX-License-Identifier: MIT
-- Hostile skill: loading a C module
name = "require_module"
documentation = "hostile input: loading a C module"
function execute()
  local m = require("socket")
  return S_FINAL
end
