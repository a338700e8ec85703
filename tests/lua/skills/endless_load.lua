-- SPDX-License-Identifier: MIT
-- Test skill: an endless loop while the file loads.
name               = "endless_load"
documentation      = "hangs at load"
while true do end  -- MARK
