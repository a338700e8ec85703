-- SPDX-License-Identifier: MIT
-- Test skill (plain execute()): logs every interface reading, then drives the motor.
name               = "read_sensors"
depends_interfaces = {
   {v="pose", type="Position3DInterface", id="Pose"},
   {v="sensor", type="RobotinoSensorInterface"},
   {v="light", type="RobotinoLightInterface"},
   {v="pucks", type="PuckVisionInterface"},
   {v="laser", type="Laser360Interface"},
   {v="motor", type="MotorInterface"},
}
documentation      = "reads all sensors"

function execute()
   local x, y, th = pose:get()
   printf("pose %.2f %.2f %.2f valid=%s", x, y, th, tostring(pose:is_valid()))
   printf("holder puck=%s ir=%.2f optical=%s,%s", tostring(sensor:puck_in_holder()),
          sensor:ir_distance(), tostring(sensor:optical_left()), tostring(sensor:optical_right()))
   printf("light %s visible=%s red=%s yellow=%s green=%s on=%s stable=%.1f", light:device(),
          tostring(light:visible()), light:red(), light:yellow(), light:green(),
          tostring(light:green() == light.ON), light:stable_for())
   local px, py, d = pucks:nearest()
   printf("pucks %d nearest %.2f %.2f %.2f", pucks:count(), px, py, d)
   printf("laser %d ahead %.2f", laser:num_beams(), laser:min_distance(-0.05, 0.05))
   motor:set_velocity(0.25, 0, 0.5)
   return S_FINAL
end
