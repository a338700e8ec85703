; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- the task engine. The decision rules (exploration, production) assert
; one (task) at a time; this file takes it through
;   NEW -> LOCKING (if it needs a resource) -> START -> RUNNING -> DONE | FAILED
; by requesting the lock, calling the task's skill and reading the skill's outcome. Whoever
; asserted the task consumes DONE/FAILED (and then calls task-finished).
;
; Resources: (resource-request (resource ?r)) asks for one, (resource-granted (resource ?r)) /
; (resource-denied (resource ?r)) answer, (resource-release (resource ?r)) gives it back;
; 26_locks.clp maps these onto the lock protocol, or grants everything at once without it.

(deffunction task-skill (?kind)
  (switch ?kind
    (case EXPLORE then explore_machine)
    (case GET_S0 then get_s0)
    (case GET_CONSUMED then get_consumed)
    (case FINISH then finish_puck_at)
    (case DELIVER then deliver)
    (case LEAVE then leave_puck)
    (case PARK then park)
    (default NONE))
)

(defrule task-needs-lock
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state NEW) (lock ?r&~NONE))
  =>
  (assert (resource-request (resource ?r)))
  (modify ?t (state LOCKING) (since (now)))
)

(defrule task-no-lock
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state NEW) (lock NONE))
  =>
  (modify ?t (state START))
)

(defrule task-resource-granted
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state LOCKING) (lock ?r))
  (resource-granted (resource ?r))
  =>
  (modify ?t (state START))
)

(defrule task-resource-denied
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state LOCKING) (lock ?r) (attempts ?a))
  ?d <- (resource-denied (resource ?r))
  =>
  (retract ?d)
  (modify ?t (state LOCK_WAIT) (since (now)) (attempts (+ ?a 1)))
)

; Ask again after a second (the decision rules may drop the task instead: see task-abandon).
(defrule task-lock-retry
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state LOCK_WAIT) (lock ?r) (since ?s))
  (time ? ?)                    ; after the task: a new (time) fact meets only waiting tasks
  (test (> (- (now) ?s) 1.0))   ; a test CE: evaluated again with every new (time) fact
  =>
  (assert (resource-request (resource ?r)))
  (modify ?t (state LOCKING) (since (now)))
)

; A LEAVE task carries the puck it leaves out of the way (leave_puck place AWAY: a dump spot at a
; wall): left where the robot stands -- in front of the storage or a machine -- it would be
; swept into the holder of the next robot driving there, over and over.
(deffunction task-place (?kind ?place)
  (if (and (eq ?kind LEAVE) (eq ?place NONE)) then (return AWAY))
  (return ?place)
)

(defrule task-start
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state START) (kind ?k&~WAIT) (place ?place))
  =>
  (bind ?skill (task-skill ?k))
  (bind ?p (task-place ?k ?place))
  (if (eq ?p NONE)
   then (skill-call ?skill)
   else (skill-call ?skill place ?p))
  (modify ?t (state RUNNING) (since (now)))
)

(defrule task-start-wait
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state START) (kind WAIT))
  =>
  (modify ?t (state RUNNING) (since (now)))
)

(defrule task-wait-over
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state RUNNING) (kind WAIT) (since ?s))
  (time ? ?)
  (test (> (- (now) ?s) 3.0))
  =>
  (modify ?t (state DONE))
)

; A skill aborted by a newer skill-call reports FAILED "aborted by skill-call ..."; that is not
; the outcome of the task's current skill (which may have the same name).
(defrule task-skill-aborted
  (declare (salience (+ ?*PRIORITY-TASK* 1)))
  ?s <- (skill (status FAILED) (error ?e&:(eq (str-index "aborted by skill-call" ?e) 1)))
  =>
  (retract ?s)
)

(defrule task-skill-final
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state RUNNING) (kind ?k))
  ?s <- (skill (name ?n&:(eq ?n (str-cat (task-skill ?k)))) (status FINAL) (result ?r))
  =>
  (retract ?s)
  (modify ?t (state DONE) (result ?r))
)

(defrule task-skill-failed
  (declare (salience ?*PRIORITY-TASK*))
  ?t <- (task (state RUNNING) (kind ?k))
  ?s <- (skill (name ?n&:(eq ?n (str-cat (task-skill ?k)))) (status FAILED) (error ?e) (result ?r))
  =>
  (retract ?s)
  (log-warn "task " ?k " failed: " ?e)
  (modify ?t (state FAILED) (error ?e) (result ?r))
)

; Called by the consumer of a DONE/FAILED task: releases its lock, counts, retracts it.
(deffunction task-finished (?t ?ok)
  (bind ?r (fact-slot-value ?t lock))
  (if (neq ?r NONE) then (assert (resource-release (resource ?r))))
  (do-for-fact ((?rec record)) TRUE
    (if ?ok
     then (modify ?rec (tasks-done (+ ?rec:tasks-done 1)) (failures-in-a-row 0))
     else (modify ?rec (tasks-failed (+ ?rec:tasks-failed 1))
                       (failures-in-a-row (+ ?rec:failures-in-a-row 1)))))
  (retract ?t)
)

; A phase change ends whatever the robot was doing (exploration tasks in production, ...).
(defrule task-phase-changed
  (declare (salience ?*PRIORITY-TASK*))
  (game (phase ?ph))
  ?t <- (task (kind EXPLORE) (state ?st))
  (test (neq ?ph EXPLORATION))
  =>
  (if (eq ?st RUNNING) then (skill-stop))
  (bind ?r (fact-slot-value ?t lock))
  (if (neq ?r NONE) then (assert (resource-release (resource ?r))))
  (retract ?t)
)
