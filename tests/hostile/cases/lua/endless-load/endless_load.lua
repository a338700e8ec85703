-- SPDX-License-Identifier: MIT
-- Hostile skill: an endless loop while the file loads
name = "endless_load"
documentation = "x"
while true do end
