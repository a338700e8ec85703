-- SPDX-License-Identifier: MIT
-- machine_front: a helper module of the skill library, no skill (require("machine_front")):
-- where get_consumed and finish_puck_at stop before a machine's input.

-- drive_to's arguments for the pose `dist` m before the input place of machine `place` (its
-- RFID reader), facing the machine, driven forwards only. `navigator` is the calling skill's
-- NavigatorInterface (the module has no interfaces of its own).
function before_input(navigator, place, dist)
   local px, py, pth = navigator:place(place .. "_input")
   return {x = px - math.cos(pth) * dist, y = py - math.sin(pth) * dist, ori = pth,
           forward_only = true}
end
