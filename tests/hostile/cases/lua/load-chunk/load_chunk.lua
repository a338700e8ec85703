-- SPDX-License-Identifier: MIT
-- Hostile skill: compiling code at run time
name = "load_chunk"
documentation = "hostile input: compiling code at run time"
function execute()
  local f = load("return 1")
  return S_FINAL
end
