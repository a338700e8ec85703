; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- templates and the static field.

; A device of the field and what this robot believes about it.
(deftemplate machine
  (slot name (type SYMBOL))
  (slot mtype (type SYMBOL) (default UNKNOWN))   ; T1..T5 RECYCLE DELIVER TEST UNKNOWN
  (slot x (type FLOAT) (default 0.0))
  (slot y (type FLOAT) (default 0.0))
  (multislot loaded-with (type SYMBOL))          ; intermediate inputs lying beside it: S0 S1 S2
  (slot consumed (type INTEGER) (default 0))     ; consumed pucks lying beside it
  (slot down-until (type FLOAT) (default 0.0))   ; believed down (red) until then
  (slot updated-at (type FLOAT) (default 0.0))   ; time of the latest change (world-model sync)
  (slot explored (type SYMBOL) (default FALSE))  ; reported in the exploration phase
)

; The exploration code of a machine type (from the refbox's ExplorationInfo).
(deftemplate signal
  (slot type (type SYMBOL))
  (slot code (type STRING))   ; "red=ON yellow=OFF green=BLINK", as explore_machine reports
)

; An active order (from OrderInfo).
(deftemplate order
  (slot id (type INTEGER))
  (slot product (type SYMBOL))       ; P1 P2 P3
  (slot requested (type INTEGER))
  (slot delivered (type INTEGER))
  (slot begin (type INTEGER))
  (slot end (type INTEGER))
)

; The refbox's game state as last heard.
(deftemplate game
  (slot phase (type SYMBOL) (default PRE_GAME))
  (slot state (type SYMBOL) (default INIT))
  (slot time (type FLOAT) (default 0.0))     ; phase game time (s)
)

; What this robot holds: NONE S0 S1 S2 P1 P2 P3 CONSUMED.
(deftemplate holding (slot puck (type SYMBOL) (default NONE)))

; The robot's role in production.
(deftemplate role (slot name (type SYMBOL) (default P3)) (slot target (type SYMBOL) (default NONE)))

; Bookkeeping of outcomes (role change, statistics).
(deftemplate record
  (slot failures-in-a-row (type INTEGER) (default 0))
  (slot complex-delivered (type INTEGER) (default 0))
  (slot tasks-done (type INTEGER) (default 0))
  (slot tasks-failed (type INTEGER) (default 0))
)

; The current task: one at a time (see 50_tasks.clp).
(deftemplate task
  (slot kind (type SYMBOL))            ; EXPLORE GET_S0 GET_CONSUMED FINISH DELIVER LEAVE PARK WAIT
  (slot place (type SYMBOL) (default NONE))
  (slot lock (type SYMBOL) (default NONE))
  (slot state (type SYMBOL) (default NEW))   ; NEW LOCKING LOCK_WAIT START RUNNING DONE FAILED
  (slot since (type FLOAT) (default 0.0))
  (slot attempts (type INTEGER) (default 0))
  (slot result (type STRING) (default ""))
  (slot error (type STRING) (default ""))
)

; Small bookkeeping facts (templates so that fact queries can use them from the start).
(deftemplate explored-by-me (slot machine (type SYMBOL)) (slot type (type SYMBOL)))
(deftemplate explore-skip (slot machine (type SYMBOL)) (slot until (type FLOAT)))
(deftemplate explore-pos (slot machine (type SYMBOL)))
(deftemplate recycle-pending)
(deftemplate task-cooldown (slot until (type FLOAT)))
(deftemplate resource-request (slot resource (type SYMBOL)))
(deftemplate resource-granted (slot resource (type SYMBOL)))
(deftemplate resource-denied (slot resource (type SYMBOL)))
(deftemplate resource-release (slot resource (type SYMBOL)))

(deffacts llsf2013-static
  (game)
  (holding)
  (record)
  ; The 2013 field (rule book poses).
  (machine (name M1) (x 3.92) (y 1.68)) (machine (name M2) (x 3.92) (y 3.92))
  (machine (name M3) (x 2.80) (y 0.56)) (machine (name M4) (x 2.80) (y 1.68))
  (machine (name M5) (x 2.80) (y 2.80)) (machine (name M6) (x 2.80) (y 3.92))
  (machine (name M7) (x 2.80) (y 5.04)) (machine (name M8) (x 1.68) (y 1.68))
  (machine (name M9) (x 1.68) (y 3.92)) (machine (name M10) (x 1.68) (y 5.04))
  (machine (name R1) (mtype RECYCLE) (x 5.40) (y 0.20))
  (machine (name R2) (mtype RECYCLE) (x 0.20) (y 5.40))
  (machine (name TST) (mtype TEST) (x 5.40) (y 5.40))
  (machine (name D1) (mtype DELIVER) (x 5.34) (y 3.15))
  (machine (name D2) (mtype DELIVER) (x 5.34) (y 2.80))
  (machine (name D3) (mtype DELIVER) (x 5.34) (y 2.45))
  ; The exploration ring (a closed path past all machines) and per-robot start machines.
  (exploration-ring M8 M4 M3 M1 M2 M6 M7 M10 M9 M5)
)

; Euclidean distance between the robot and a machine.
(deffunction distance-to (?x ?y ?mx ?my)
  (sqrt (+ (* (- ?mx ?x) (- ?mx ?x)) (* (- ?my ?y) (- ?my ?y))))
)

; The value of a confval, or ?default if it is not configured.
; (fact-by-slot: the confval by its path, the fact find-fact would give, without a query)
(deffunction cfg (?path ?default)
  (bind ?c (fact-by-slot confval path ?path))
  (if (not ?c) then (return ?default))
  (return (fact-slot-value ?c value))
)
(deffunction cfg-list (?path $?default)
  (bind ?c (fact-by-slot confval path ?path))
  (if (not ?c) then (return ?default))
  (return (fact-slot-value ?c list-value))
)
