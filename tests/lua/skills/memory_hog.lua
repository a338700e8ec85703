-- SPDX-License-Identifier: MIT
-- Test skill (plain execute()): allocates far beyond the interpreter's heap limit.
name               = "memory_hog"
documentation      = "allocates too much"
function execute()
   local s = string.rep("x", 1 << 30)  -- MARK
   return S_FINAL, s
end
