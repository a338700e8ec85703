-- SPDX-License-Identifier: MIT
-- A helper module inside a skill directory (no skill: nothing of a skill is declared), required
-- by drive_node.lua.
require("fawkes.modinit")
module(..., fawkes.modinit.module_init)

approach = {M1 = "M1_APPROACH"}
