; SPDX-License-Identifier: MIT
; Built-in: time (clips/src/time_feature.cpp). Each cycle the host asserts (time sec usec) and
; retracts it when the cycle's rules have run (Fawkes' agents do that with a rule of salience
; -10000, time-retract; the host does it without a rule firing in every cycle). Functions:
; (now), (time-diff ?t1 ?t2), (time-diff-sec ?t1 ?t2), (timeout ?now ?since ?secs), (time> ?t1 ?t2).

; Periodic actions: (timer (name beacon) (time $?t&:(timeout ?now ?t 1.0))) => modify (time ?now).
(deftemplate timer
  (slot name)
  (multislot time (type INTEGER) (cardinality 2 2) (default 0 0))
  (slot seq (type INTEGER) (default 1))
)
