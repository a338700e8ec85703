; SPDX-License-Identifier: MIT
; Built-in: time (clips/src/time_feature.cpp). Each cycle the host asserts (time sec usec) and
; retracts it when the cycle's rules have run (Fawkes' agents do that with a rule of salience
; -10000, time-retract; the host does it without a rule firing in every cycle). Functions:
; (now) (seconds as FLOAT; in Fawkes-style agents (sec usec)), (time-diff ?t1 ?t2), (time-diff-sec ?t1 ?t2), (timeout ?now ?since ?secs), (time> ?t1 ?t2).

; (now-sec-usec): the cycle's time as (sec usec); in Fawkes-style agents (now) is the same.

; Periodic actions: (timer (name beacon) (time $?t&:(timeout ?now ?t 1.0))) => modify (time ?now).
; As in Fawkes' time.clp, a timer asserted without a time starts at the current time.
(deftemplate timer
  (slot name)
  (multislot time (type INTEGER) (cardinality 2 2) (default-dynamic (now-sec-usec)))
  (slot seq (type INTEGER) (default 1))
)
