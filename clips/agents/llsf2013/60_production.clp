; SPDX-License-Identifier: MIT
; LLSF 2013 team agent -- production: incremental task-level reasoning with roles (thesis §3.3,
; §5.3). Each decision looks only at what the robot holds, its role and the shared world model:
;   holding nothing -> get an S0 (or, recycling "ifpossible", a consumed puck beside a machine)
;   holding S0/S1/S2 -> the machine this puck should go to for the role's product
;   holding a product -> deliver;  holding a consumed puck -> the nearer recycler
; Roles: P3 (S0 -> T5 -> deliver), P1 (T3), P2 (T4), P1P2 (T3 or T4, whichever lies farther
; from the T5). Configuration (confval, /clips-agent/...): roles (list by robot
; number), recycle (never | ifpossible | afterdeliver), recycle-when-empty (TRUE: a consumed
; puck when the storage looked empty, whatever recycle says), role-change/after-complex-delivery,
; role-change/time-left (s), role-change/failures (in a row). See docs/agent-llsf2013.md.

; The storage looked empty (get_s0 saw no puck): until then wait (or, with recycle-when-empty,
; take a consumed puck) instead.
(deftemplate storage-empty (slot until (type FLOAT)))

(deffunction robot-x () (bind ?p (find-fact ((?f pose)) TRUE))
  (if (= (length$ ?p) 0) then (return 0.5)) (return (fact-slot-value (nth$ 1 ?p) x)))
(deffunction robot-y () (bind ?p (find-fact ((?f pose)) TRUE))
  (if (= (length$ ?p) 0) then (return 1.0)) (return (fact-slot-value (nth$ 1 ?p) y)))

(deffunction type-inputs (?type)
  (switch ?type
    (case T1 then (create$ S0))
    (case T2 then (create$ S0 S1))
    (case T3 then (create$ S0 S1 S2))
    (case T4 then (create$ S0 S1 S2))
    (case T5 then (create$ S0))
    (case RECYCLE then (create$ CONSUMED))
    (default (create$)))
)

(deffunction type-output (?type)
  (switch ?type
    (case T1 then S1) (case T2 then S2) (case T3 then P1) (case T4 then P2) (case T5 then P3)
    (case RECYCLE then S0)
    (default UNKNOWN))
)

(deffunction machine-up (?m)
  (any-factp ((?x machine)) (and (eq ?x:name ?m) (<= ?x:down-until (now))))
)

(deffunction machine-slot (?m ?slot)
  (fact-slot-value (nth$ 1 (find-fact ((?x machine)) (eq ?x:name ?m))) ?slot)
)

; Inputs machine ?m still needs for its current set.
(deffunction machine-needs (?m)
  (bind ?needs (create$))
  (bind ?loaded (machine-slot ?m loaded-with))
  (foreach ?i (type-inputs (machine-slot ?m mtype))
    (if (not (member$ ?i ?loaded)) then (bind ?needs (create$ ?needs ?i))))
  (return ?needs)
)

; The up machine of ?type nearest to (?x, ?y) whose loaded-with equals $?loaded (any if the
; list is (ANY)); NONE if there is none.
(deffunction nearest-machine (?type ?x ?y $?loaded)
  (bind ?best NONE) (bind ?bd 1000.0)
  (do-for-all-facts ((?m machine))
      (and (eq ?m:mtype ?type) (<= ?m:down-until (now))
           (or (eq ?loaded (create$ ANY)) (eq ?m:loaded-with ?loaded)))
    (bind ?d (distance-to ?x ?y ?m:x ?m:y))
    (if (< ?d ?bd) then (bind ?bd ?d) (bind ?best ?m:name)))
  (return ?best)
)

(deffunction nearest-consumed (?x ?y)
  (bind ?best NONE) (bind ?bd 1000.0)
  (do-for-all-facts ((?m machine)) (> ?m:consumed 0)
    (bind ?d (distance-to ?x ?y ?m:x ?m:y))
    (if (< ?d ?bd) then (bind ?bd ?d) (bind ?best ?m:name)))
  (return ?best)
)

; Where a held intermediate (?h = S0, S1 or S2) goes for a complex product at ?target.
(deffunction feed-machine (?target ?h ?x ?y)
  (bind ?needs (machine-needs ?target))
  (bind ?up (machine-up ?target))
  (if (and ?up (member$ ?h ?needs)) then (return ?target))
  (switch ?h
    (case S0 then
      (if (member$ S1 ?needs) then (return (nearest-machine T1 ?x ?y ANY)))
      (if (member$ S2 ?needs) then
        (bind ?m (nearest-machine T2 ?x ?y S1))
        (if (neq ?m NONE) then (return ?m))
        (bind ?m (nearest-machine T2 ?x ?y))
        (if (neq ?m NONE) then (return ?m))
        (return (nearest-machine T1 ?x ?y ANY))))
    (case S1 then
      (if (member$ S2 ?needs) then
        (bind ?m (nearest-machine T2 ?x ?y S0))
        (if (neq ?m NONE) then (return ?m))
        (return (nearest-machine T2 ?x ?y)))))
  (return NONE)
)

; The next task for the role: (kind place lock).
(deffunction prod-next-step (?role ?target ?h)
  (bind ?x (robot-x)) (bind ?y (robot-y))
  (switch ?h
    (case NONE then
      (bind ?mode (cfg "/clips-agent/recycle" "never"))
      (bind ?empty (any-factp ((?e storage-empty)) (> ?e:until (now))))
      ; The storage looked empty: a consumed puck instead only if recycle-when-empty says so
      ; (default FALSE: recycle "never" never recycles).
      (bind ?when-empty (and ?empty (eq (cfg "/clips-agent/recycle-when-empty" FALSE) TRUE)))
      (if (or ?when-empty (eq ?mode "ifpossible")
              (and (eq ?mode "afterdeliver") (any-factp ((?rp recycle-pending)) TRUE))) then
        (bind ?cm (nearest-consumed ?x ?y))
        (if (neq ?cm NONE) then (return (create$ GET_CONSUMED ?cm ?cm))))
      (if ?empty then (return (create$ WAIT NONE NONE)))
      (return (create$ GET_S0 NONE INS)))
    (case CONSUMED then
      (bind ?r (nearest-machine RECYCLE ?x ?y ANY))
      (if (eq ?r NONE) then (return (create$ WAIT NONE NONE)))
      (return (create$ FINISH ?r ?r)))
    (case P1 then (return (create$ DELIVER NONE DELIVERY)))
    (case P2 then (return (create$ DELIVER NONE DELIVERY)))
    (case P3 then (return (create$ DELIVER NONE DELIVERY)))
    (case UNKNOWN then (return (create$ LEAVE NONE NONE))))
  ; S0, S1, S2
  (if (eq ?role P3) then
    (if (neq ?h S0) then (return (create$ LEAVE NONE NONE)))
    (bind ?t5 (nearest-machine T5 ?x ?y ANY))
    (if (eq ?t5 NONE) then (return (create$ WAIT NONE NONE)))
    (return (create$ FINISH ?t5 ?t5)))
  (bind ?m (feed-machine ?target ?h ?x ?y))
  (if (eq ?m NONE) then (return (create$ WAIT NONE NONE)))
  (return (create$ FINISH ?m ?m))
)

; --- roles ------------------------------------------------------------------------------------

(deffunction complex-target (?role)
  (bind ?t5 (nearest-machine T5 0.0 0.0 ANY))
  (bind ?t5x (if (eq ?t5 NONE) then 0.0 else (machine-slot ?t5 x)))
  (bind ?t5y (if (eq ?t5 NONE) then 0.0 else (machine-slot ?t5 y)))
  (bind ?t3 (nearest-machine T3 0.0 0.0 ANY))
  (bind ?t4 (nearest-machine T4 0.0 0.0 ANY))
  (if (eq ?role P1) then (return ?t3))
  (if (eq ?role P2) then (return ?t4))
  ; P1P2: the one farther from the T5 (less crossing with the P3 robots)
  (if (eq ?t3 NONE) then (return ?t4))
  (if (eq ?t4 NONE) then (return ?t3))
  (if (> (distance-to ?t5x ?t5y (machine-slot ?t3 x) (machine-slot ?t3 y))
         (distance-to ?t5x ?t5y (machine-slot ?t4 x) (machine-slot ?t4 y)))
   then (return ?t3) else (return ?t4))
)

(defrule prod-role-init
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION))
  (not (role))
  (machine (mtype T5))
  (machine (mtype T3))
  (machine (mtype T4))
  =>
  (bind ?roles (cfg-list "/clips-agent/roles" "P1P2" "P3" "P3"))
  (bind ?n (+ (mod (- ?*ROBOT-NUMBER* 1) (length$ ?roles)) 1))
  (bind ?role (sym-cat (nth$ ?n ?roles)))
  (bind ?target (if (eq ?role P3) then NONE else (complex-target ?role)))
  (log-info "production: role " ?role (if (eq ?target NONE) then "" else (str-cat " at " ?target)))
  (assert (role (name ?role) (target ?target)))
)

(deffunction change-role (?r ?why)
  ; The outcome as data (the role_changes statistic counts these, docs/statistics.md); the log
  ; line is for people and may say anything.
  (agent-event role-change (fact-slot-value ?r name) P3 ?why)
  (log-info "production: role change " (fact-slot-value ?r name) " -> P3 (" ?why ")")
  (modify ?r (name P3) (target NONE))
)

(defrule prod-role-change-after-delivery
  (declare (salience ?*PRIORITY-DECIDE*))
  ?r <- (role (name ~P3))
  (record (complex-delivered ?n&:(> ?n 0)))
  (test (eq (cfg "/clips-agent/role-change/after-complex-delivery" FALSE) TRUE))
  =>
  (change-role ?r "a complex product was delivered")
)

; Too little time left to start another complex product (thesis §5.3.3: "not reasonable to start
; a second production"; the 2013 agent changed "when nothing is loaded"): only between two
; productions -- the target machine has nothing loaded and the robot holds no intermediate. A
; production under way is finished.
(defrule prod-role-change-time-left
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (time ?gt))
  ?r <- (role (name ~P3) (target ?t))
  (holding (puck NONE|S0))
  (machine (name ?t) (loaded-with))
  (test (> (cfg "/clips-agent/role-change/time-left" 0) 0))
  (test (> ?gt (- ?*PRODUCTION-TIME* (cfg "/clips-agent/role-change/time-left" 0))))
  =>
  (change-role ?r "too little time left for a complex product")
)

(defrule prod-role-change-failures
  (declare (salience ?*PRIORITY-DECIDE*))
  ?r <- (role (name ~P3))
  (record (failures-in-a-row ?f))
  (test (> (cfg "/clips-agent/role-change/failures" 0) 0))
  (test (>= ?f (cfg "/clips-agent/role-change/failures" 0)))
  =>
  (change-role ?r (str-cat ?f " failures in a row"))
)

; --- deciding ---------------------------------------------------------------------------------

(defrule prod-decide
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (state RUNNING))
  (role (name ?role) (target ?target))
  (holding (puck ?h))
  (not (task))
  (time ? ?)
  =>
  (bind ?step (prod-next-step ?role ?target ?h))
  (assert (task (kind (nth$ 1 ?step)) (place (nth$ 2 ?step)) (lock (nth$ 3 ?step))))
)

(deffunction set-holding (?p)
  (do-for-fact ((?h holding)) TRUE (modify ?h (puck ?p)))
)

(deffunction machine-update (?m $?changes)
  ; ?changes: slot value pairs, e.g. (loaded-with-add S1) (consumed-add 1)
  (do-for-fact ((?x machine)) (eq ?x:name ?m)
    (bind ?loaded ?x:loaded-with) (bind ?consumed ?x:consumed) (bind ?down ?x:down-until)
    (bind ?i 1)
    (while (< ?i (length$ ?changes))
      (bind ?k (nth$ ?i ?changes)) (bind ?v (nth$ (+ ?i 1) ?changes))
      (switch ?k
        (case loaded-add then (bind ?loaded (create$ ?loaded ?v)))
        (case loaded-clear then (bind ?consumed (+ ?consumed (length$ ?loaded)))
                                (bind ?loaded (create$)))
        (case consumed-add then (bind ?consumed (max 0 (+ ?consumed ?v))))
        (case consumed-set then (bind ?consumed ?v))
        (case down-until then (bind ?down ?v)))
      (bind ?i (+ ?i 2)))
    (modify ?x (loaded-with ?loaded) (consumed ?consumed) (down-until ?down)
               (updated-at (now))))
)

(defrule prod-get-s0-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind GET_S0) (state DONE))
  =>
  (set-holding S0)
  (task-finished ?t TRUE)
)

(defrule prod-get-consumed-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind GET_CONSUMED) (state DONE) (place ?m))
  =>
  (set-holding CONSUMED)
  (log-info "production: took a consumed puck at " ?m)
  (machine-update ?m consumed-add -1)
  (task-finished ?t TRUE)
)

(defrule prod-finish-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind FINISH) (state DONE) (place ?m) (result ?r))
  (holding (puck ?h))
  =>
  (if (eq ?r "WAITING")
   then
    (machine-update ?m loaded-add ?h)
    (set-holding NONE)
   else
    (bind ?type (machine-slot ?m mtype))
    (machine-update ?m loaded-clear x)
    (set-holding (type-output ?type))
    (if (eq ?type RECYCLE) then
      (do-for-all-facts ((?p recycle-pending)) TRUE (retract ?p))))
  (task-finished ?t TRUE)
)

(defrule prod-deliver-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind DELIVER) (state DONE))
  (holding (puck ?h))
  ?rec <- (record (complex-delivered ?n))
  =>
  (set-holding NONE)
  (if (member$ ?h (create$ P1 P2)) then
    (modify ?rec (complex-delivered (+ ?n 1)))
    (if (eq (cfg "/clips-agent/recycle" "never") "afterdeliver") then
      (assert (recycle-pending))))
  (task-finished ?t TRUE)
)

(defrule prod-leave-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind LEAVE|PARK|WAIT) (state DONE))
  =>
  (if (eq (fact-slot-value ?t kind) LEAVE) then (set-holding NONE))
  (task-finished ?t TRUE)
)

(defrule prod-task-failed
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION))
  ?t <- (task (kind ?k&~EXPLORE) (state FAILED) (place ?m) (error ?e))
  =>
  (if (or (str-index "no puck in the holder" ?e) (str-index "lost the puck" ?e)) then
    (set-holding NONE))
  (if (str-index "already holding a puck" ?e) then (set-holding UNKNOWN))
  (if (str-index "rejected the puck" ?e) then
    ; A multi-input machine that rejects an S0/S1/S2 has one of that kind already: an earlier
    ; insert that failed half-way (the robot stuck after the puck reached the reader) still
    ; counted. Note it, or the next puck of this kind is brought to the same machine again.
    (bind ?held (fact-slot-value (nth$ 1 (find-fact ((?x holding)) TRUE)) puck))
    (if (and (member$ (machine-slot ?m mtype) (create$ T2 T3 T4))
             (member$ ?held (type-inputs (machine-slot ?m mtype)))
             (not (member$ ?held (machine-slot ?m loaded-with)))) then
      (machine-update ?m loaded-add ?held))
    (set-holding UNKNOWN))
  (if (str-index "is down (red)" ?e) then (machine-update ?m down-until (+ (now) 30.0)))
  (if (and (eq ?k GET_S0) (str-index "no puck seen" ?e)) then
    ; Look again in 30 s (pucks may be pushed back, late-order pucks arrive); meanwhile wait, or
    ; recycle with recycle-when-empty.
    (assert (storage-empty (until (+ (now) 30.0)))))
  (if (and (eq ?k GET_CONSUMED)
           (or (str-index "no puck beside" ?e) (str-index "INVALID_GOAL" ?e))) then
    ; None there, or none the robot can reach (lying too close to a wall to drive up to):
    ; forget them, or every robot tries again and again.
    (machine-update ?m consumed-set 0))
  (if (and (eq ?k DELIVER) (or (str-index "refused" ?e) (str-index "no active gate" ?e))) then
    (assert (task-cooldown (until (+ (now) 10.0)))))
  (task-finished ?t FALSE)
)

; After a refused delivery the product is held a while before the next attempt.
(defrule prod-cooldown
  (declare (salience (+ ?*PRIORITY-DECIDE* 1)))
  ?c <- (task-cooldown (until ?until))
  (not (task))
  (time ? ?)
  =>
  (if (> ?until (now))
   then (assert (task (kind WAIT)))
   else (retract ?c))
)
