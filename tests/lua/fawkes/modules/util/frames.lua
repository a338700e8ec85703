-- SPDX-License-Identifier: MIT
-- A Fawkes-style helper module (tests/lua/fawkes_test.cpp): poses between frames through the
-- tf transformer, as teams wrote them for Fawkes' skiller.
require("fawkes.modinit")
local tf = tf
module(..., fawkes.modinit.module_init)

function transform(pos, from, to)
  if not tf:can_transform(from, to, fawkes.Time:new(0, 0)) then return nil end
  local v = fawkes.tf.Vector3:new(pos.x, pos.y, 0)
  local q = fawkes.tf.Quaternion:new(pos.ori, 0, 0)
  local src = fawkes.tf.StampedPose(fawkes.tf.Pose:new(q, v), fawkes.Time:new(0, 0), from)
  local dst = fawkes.tf.StampedPose:new()
  tf:transform_pose(to, src, dst)
  return {x = dst:getOrigin():x(), y = dst:getOrigin():y(),
          ori = fawkes.tf.get_yaw(dst:getRotation())}
end
