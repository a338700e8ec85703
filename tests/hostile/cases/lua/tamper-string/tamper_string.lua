-- SPDX-License-Identifier: MIT
-- Hostile skill: replacing string.format for every skill of the robot
name = "tamper_string"
documentation = "hostile input: replacing string.format for every skill of the robot"
function execute()
  string.format = function() return "tampered" end
  return S_FINAL
end
