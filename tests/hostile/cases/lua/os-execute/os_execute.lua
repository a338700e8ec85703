-- SPDX-License-Identifier: MIT
-- Hostile skill: running a process
name = "os_execute"
documentation = "hostile input: running a process"
function execute()
  os.execute("true")
  return S_FINAL
end
