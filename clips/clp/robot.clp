; SPDX-License-Identifier: MIT
; Built-in: the robot's identity and pose (clips/src/robot_feature.cpp sets them).

(defglobal
  ?*ROBOT-NAME* = robot1        ; symbol, e.g. robot1
  ?*ROBOT-NUMBER* = 1           ; integer
  ?*TEAM-NAME* = "Carologistics"
)

; Asserted after every (reset).
(deftemplate robot-info
  (slot name (type SYMBOL))
  (slot number (type INTEGER))
  (slot team (type STRING))
)

; The robot's pose in the field frame (m, m, rad); one fact, replaced when the pose changes.
(deftemplate pose
  (slot x (type FLOAT) (default 0.0))
  (slot y (type FLOAT) (default 0.0))
  (slot ori (type FLOAT) (default 0.0))
)
