-- SPDX-License-Identifier: MIT
-- Mistake (tests/app/exercise_hints_test.cpp): a skill without a state machine whose execute()
-- has a path without `return` (it returns nil). Exercise 01.
name               = "drive_to_point"
depends_skills     = {}
depends_interfaces = {}
documentation      = [==[Drives the robot to a point of the field.]==]

function execute()  -- MISTAKE
   local started = true
   if not started then return S_FAILED end
end
