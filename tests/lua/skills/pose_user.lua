-- SPDX-License-Identifier: MIT
-- Test skill (plain execute()): reads the pose (whose implementation may throw).
name               = "pose_user"
depends_interfaces = { {v="pose", type="Position3DInterface"} }
documentation      = "reads the pose"
function execute()
   local x = pose:x()  -- MARK
   return x > -100 and S_FINAL or S_FAILED
end
