-- SPDX-License-Identifier: MIT
-- Hostile skill: opening a file
name = "io_open"
documentation = "hostile input: opening a file"
function execute()
  local f = io.open("/etc/passwd")
  return S_FINAL
end
