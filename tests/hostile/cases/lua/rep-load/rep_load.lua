-- SPDX-License-Identifier: MIT
-- Hostile skill: string.rep of 2^40 bytes while the file loads
name = "rep_load"
documentation = "x"
local s = string.rep("x", 2^40)
