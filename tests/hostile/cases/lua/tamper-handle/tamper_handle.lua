-- SPDX-License-Identifier: MIT
-- Hostile skill: breaking a library skill other skills call
name = "tamper_handle"
documentation = "hostile input: breaking a library skill other skills call"
depends_skills = {"drive_to"}
function execute()
  drive_to.fsm = nil
  return S_FINAL
end
