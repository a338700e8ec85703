; SPDX-License-Identifier: MIT
; Auction agent -- the winner's side: accepting an award and running the task it won (au-job)
; as steps of the common task engine; outcomes update what the robot holds and the world model.
; Without a task, a robot holding a product delivers it, a consumed puck recycles it, an S2
; brings it to a complex target that needs one, an S1 is kept s1-hold s (for a FEED ... S1
; task) and then put down; an S0 is kept for the next task.

(deffunction au-set-holding (?p)
  (do-for-fact ((?h holding)) TRUE (if (neq ?h:puck ?p) then (modify ?h (puck ?p)))))

; Change machine ?m's entry (as 60_production.clp of llsf2013) and share it at once.
(deffunction au-machine-update (?m ?what ?v)
  (do-for-fact ((?x machine)) (eq ?x:name ?m)
    (bind ?loaded ?x:loaded-with) (bind ?consumed ?x:consumed) (bind ?down ?x:down-until)
    (switch ?what
      (case loaded-add then (bind ?loaded (create$ ?loaded ?v)))
      (case loaded-clear then (bind ?consumed (+ ?consumed (length$ ?loaded)))
                              (bind ?loaded (create$)))
      (case consumed-add then (bind ?consumed (max 0 (+ ?consumed ?v))))
      (case consumed-set then (bind ?consumed ?v))
      (case down-until then (bind ?down ?v)))
    (modify ?x (loaded-with ?loaded) (consumed ?consumed) (down-until ?down)
               (updated-at (now))))
  ; the next Worldmodel broadcast goes out in this cycle (40_worldmodel.clp's timer)
  (do-for-fact ((?t timer)) (eq ?t:name worldmodel) (modify ?t (time 0 0)))
)

; A task of this robot ended: remember the outcome for the heartbeats (the 3 newest).
(deffunction au-job-end (?j ?ok)
  (bind ?id (fact-slot-value ?j auction))
  (log-info "task " (fact-slot-value ?j key) " (auction " ?id ") " (if ?ok then "done" else "failed"))
  (au-stat (if ?ok then done else failed))
  (assert (au-done (auction ?id) (ok ?ok) (at (now))))
  (bind ?all (find-all-facts ((?d au-done)) TRUE))
  (while (> (length$ ?all) 3)
    (bind ?old (nth$ 1 ?all))
    (foreach ?d ?all (if (< (fact-slot-value ?d at) (fact-slot-value ?old at)) then (bind ?old ?d)))
    (retract ?old)
    (bind ?all (find-all-facts ((?d au-done)) TRUE)))
  (retract ?j)
  (au-status-now)
)

; Give up the current task for a better one (it is auctioned again by its auctioneer).
(deffunction au-drop-job (?j)
  (do-for-all-facts ((?t task)) TRUE
    (if (eq ?t:state RUNNING) then (skill-stop))
    (task-finished ?t FALSE))   ; releases its resource
  ; the stopped skill's FAILED fact must not end the next task that calls the same skill
  (do-for-all-facts ((?s skill)) (neq ?s:status RUNNING) (retract ?s))
  (log-info "dropping task " (fact-slot-value ?j key) " for a better one")
  (au-job-end ?j FALSE)
)

; A skill string replaced by a new skill-call is reported FAILED ("aborted by skill-call ...");
; that fact belongs to no task any more (the engine's task-skill-failed would take it for the
; new task when both call the same skill).
(defrule au-skill-aborted
  (declare (salience (+ ?*PRIORITY-TASK* 1)))
  ?s <- (skill (status FAILED) (error ?e&:(str-index "aborted by skill-call" ?e)))
  =>
  (retract ?s)
)

(defrule au-award
  (declare (salience ?*PRIORITY-DECIDE*))
  ?w <- (au-award-in (auction ?id) (key ?key) (prio ?prio) (auctioneer ?who))
  (game (phase ?phase))
  =>
  (retract ?w)
  (if (or (any-factp ((?j au-job)) (= ?j:auction ?id)) (any-factp ((?d au-done)) (= ?d:auction ?id)))
   then (au-send-ack ?id ?who TRUE)   ; a resent award: answer again
   else
    (if (and (eq ?phase PRODUCTION) (>= (au-my-bid ?key ?prio) 0.0)
             (member$ ?key (au-world-tasks))
             ; a late award of a task meanwhile given to another robot
             (not (any-factp ((?p au-peer))
                    (and (eq ?p:job-key ?key) (> ?p:seen (- (now) (au-alive-timeout)))))))
     then
      (do-for-fact ((?j au-job)) TRUE (au-drop-job ?j))
      (log-info "won " ?key " (auction " ?id " of " ?who ")")
      (au-stat won)
      (assert (au-job (auction ?id) (key ?key) (kind (au-key-kind ?key))
                      (machine (au-key-machine ?key)) (input (au-key-input ?key))
                      (prio ?prio) (auctioneer ?who) (since (now))))
      (au-send-ack ?id ?who TRUE)
      (au-status-now)
     else
      (log-info "declining " ?key " (auction " ?id ")")
      (au-send-ack ?id ?who FALSE)))
)

; A declined task is not announced again at once (the world models may disagree for a moment).
(defrule au-declined-cooldown
  (declare (salience (+ ?*PRIORITY-DECIDE* 1)))
  (au-ack-in (auction ?id) (accepted FALSE))
  (au-auction (id ?id) (key ?key))
  =>
  (assert (au-cooldown (key ?key) (until (+ (now) (au-retry-delay)))))
)

; --- running a task ----------------------------------------------------------------------------

(deffunction au-cooling-down ()
  (any-factp ((?c task-cooldown)) (> ?c:until (now))))

(defrule au-job-step
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (state RUNNING))
  ?j <- (au-job (state RUNNING) (kind ?k) (machine ?m) (input ?i) (steps ?n))
  (holding (puck ?h))
  (not (task))
  (time ? ?)
  (test (not (au-cooling-down)))
  =>
  (bind ?step (au-step ?k ?m ?i ?h ?n))
  (switch (nth$ 1 ?step)
    (case DONE then (au-job-end ?j TRUE))
    (case FAIL then (au-job-end ?j FALSE))
    (default
      (modify ?j (steps (+ ?n 1)))
      (assert (task (kind (nth$ 1 ?step)) (place (nth$ 2 ?step)) (lock (nth$ 3 ?step))))))
)

(defrule au-job-failed
  (declare (salience ?*PRIORITY-DECIDE*))
  ?j <- (au-job (state FAILED))
  =>
  (au-job-end ?j FALSE)
)

; Without a task: what the robot holds decides (see the header).
(defrule au-idle-holding
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (state RUNNING))
  (not (au-job))
  (not (task))
  (holding (puck ?h&~NONE&~S0&~S1))
  (time ? ?)
  (test (not (au-cooling-down)))
  =>
  (bind ?step (au-step LOCAL NONE NONE ?h 1))
  (if (neq (nth$ 1 ?step) DONE) then
    (assert (task (kind (nth$ 1 ?step)) (place (nth$ 2 ?step)) (lock (nth$ 3 ?step)))))
)

(defrule au-idle-s1
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (state RUNNING))
  (not (au-job))
  (not (task))
  (holding (puck S1))
  (time ? ?)
  =>
  (bind ?hs (find-fact ((?x au-hold)) TRUE))
  (if (= (length$ ?hs) 0)
   then (assert (au-hold (puck S1) (until (+ (now) (au-s1-hold)))))
   else
    (if (> (now) (fact-slot-value (nth$ 1 ?hs) until)) then
      (retract (nth$ 1 ?hs))
      (assert (task (kind LEAVE)))))
)

(defrule au-hold-clear
  (declare (salience ?*PRIORITY-LOW*))
  ?f <- (au-hold)
  (holding (puck ~S1))
  =>
  (retract ?f)
)

; A step that runs far longer than any step should (robots blocking each other at the gates,
; ...) is stopped: the skill fails, the step and the task fail, the task is auctioned again.
(defrule au-step-watchdog
  (declare (salience ?*PRIORITY-DECIDE*))
  (task (state RUNNING) (kind ?k&~WAIT&~EXPLORE) (since ?s))
  (time ? ?)
  (test (> (now) (+ ?s ?*AU-STEP-TIMEOUT*)))
  (skill (status RUNNING|IDLE))
  =>
  (log-warn "step " ?k " runs for more than " ?*AU-STEP-TIMEOUT* " s: stopping it")
  (skill-stop)
)

(defrule au-task-cooldown-expired
  (declare (salience ?*PRIORITY-LOW*))
  (time ? ?)
  ?c <- (task-cooldown (until ?u))
  (test (> (now) ?u))
  =>
  (retract ?c)
)

; --- outcomes ----------------------------------------------------------------------------------

(defrule au-get-s0-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind GET_S0) (state DONE))
  =>
  (au-set-holding S0)
  (task-finished ?t TRUE)
)

(defrule au-get-consumed-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind GET_CONSUMED) (state DONE) (place ?m))
  =>
  (au-set-holding CONSUMED)
  (log-info "took a consumed puck at " ?m)
  (au-machine-update ?m consumed-add -1)
  (task-finished ?t TRUE)
)

(defrule au-finish-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind FINISH) (state DONE) (place ?m) (result ?r))
  (holding (puck ?h))
  =>
  (if (eq ?r "WAITING")
   then
    (au-machine-update ?m loaded-add ?h)
    (au-set-holding NONE)
   else
    (bind ?type (au-mslot ?m mtype))
    (au-machine-update ?m loaded-clear x)
    (au-set-holding (au-output ?type)))
  (task-finished ?t TRUE)
)

(defrule au-deliver-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind DELIVER) (state DONE))
  (holding (puck ?h))
  ?rec <- (record (complex-delivered ?n))
  =>
  (log-info "delivered " ?h)
  (au-set-holding NONE)
  (if (member$ ?h (create$ P1 P2)) then (modify ?rec (complex-delivered (+ ?n 1))))
  (task-finished ?t TRUE)
)

(defrule au-leave-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind LEAVE|PARK|WAIT) (state DONE))
  =>
  (if (eq (fact-slot-value ?t kind) LEAVE) then (au-set-holding NONE))
  (task-finished ?t TRUE)
)

(defrule au-task-failed
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION))
  ?t <- (task (kind ?k&~EXPLORE) (state FAILED) (place ?m) (error ?e))
  =>
  (if (or (str-index "no puck in the holder" ?e) (str-index "lost the puck" ?e)) then
    (au-set-holding NONE))
  (if (str-index "already holding a puck" ?e) then (au-set-holding UNKNOWN))
  (if (str-index "rejected the puck" ?e) then (au-set-holding UNKNOWN))
  (if (str-index "is down (red)" ?e) then (au-machine-update ?m down-until (+ (now) 30.0)))
  (if (and (eq ?k GET_CONSUMED) (str-index "no puck beside" ?e)) then
    (au-machine-update ?m consumed-set 0))
  (if (and (eq ?k DELIVER) (or (str-index "refused" ?e) (str-index "no active gate" ?e))) then
    (assert (task-cooldown (until (+ (now) 10.0)))))
  (do-for-fact ((?j au-job)) (eq ?j:state RUNNING) (modify ?j (state FAILED)))
  (task-finished ?t FALSE)
)
