; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- exploration. The machines lie on a ring (10_facts.clp); each robot
; starts at its own machine (confval /clips-agent/exploration/start, one per robot
; number; default M8 M2 M10) and explores the next machine along the ring that nobody has
; reported and that is not locked by another robot (a refused lock = pass it). The light code
; explore_machine reads is matched against the refbox's ExplorationInfo signals and reported
; (MachineReport), again every 2 s until the refbox's MachineReportInfo lists the machine.

(deffunction ring-after (?m)
  (bind ?ring (fact-slot-value (nth$ 1 (find-fact ((?r exploration-ring)) TRUE)) implied))
  (bind ?i (member$ ?m ?ring))
  (if (not ?i) then (return (nth$ 1 ?ring)))
  (if (= ?i (length$ ?ring)) then (return (nth$ 1 ?ring)))
  (return (nth$ (+ ?i 1) ?ring))
)

(defrule explore-init
  (game (phase EXPLORATION))
  (not (explore-pos))
  =>
  (bind ?starts (cfg-list "/clips-agent/exploration/start" "M8" "M2" "M10"))
  (bind ?n (+ (mod (- ?*ROBOT-NUMBER* 1) (length$ ?starts)) 1))
  (assert (explore-pos (machine (sym-cat (nth$ ?n ?starts)))))
  (assert (timer (name explore-report) (time 0 0) (seq 0)))
)

; The next machine to explore: from the robot's ring position on, the first one nobody has
; reported, not explored by us, and not skipped (refused lock or failure) recently.
(deffunction explore-next (?from)
  (bind ?m ?from)
  (loop-for-count 10
    (bind ?f (fact-by-slot machine name ?m))
    (if (and ?f (eq (fact-slot-value ?f explored) FALSE)
             (not (fact-by-slot explored-by-me machine ?m))
             (not (any-factp ((?s explore-skip)) (and (eq ?s:machine ?m) (> ?s:until (now))))))
     then (return ?m))
    (bind ?m (ring-after ?m)))
  (return NONE)
)

(deftemplate explore-idle (slot until (type FLOAT)))

(defrule explore-decide
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase EXPLORATION) (state RUNNING))
  (signal)
  (explore-pos (machine ?pos))
  (not (task))
  (not (explore-idle))
  (time ? ?)
  =>
  (bind ?m (explore-next ?pos))
  (if (neq ?m NONE)
   then (assert (task (kind EXPLORE) (place ?m) (lock ?m)))
   else (assert (explore-idle (until (+ (now) 1.0)))))   ; nothing to do: look again in 1 s
)

(defrule explore-idle-over
  (declare (salience ?*PRIORITY-DECIDE*))
  ?f <- (explore-idle (until ?u))
  (time ? ?)
  (test (>= (now) ?u))
  =>
  (retract ?f)
)

; Another robot holds the machine: pass it (try it again later).
(defrule explore-pass-locked
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind EXPLORE) (state LOCK_WAIT) (place ?m))
  =>
  (assert (explore-skip (machine ?m) (until (+ (now) 15.0))))
  (retract ?t)
)

(defrule explore-done
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind EXPLORE) (state DONE) (place ?m) (result ?r))
  ?p <- (explore-pos)
  =>
  (bind ?type NONE)
  (do-for-all-facts ((?s signal)) (str-index ?s:code ?r) (bind ?type ?s:type))
  (if (eq ?type NONE)
   then
    (log-warn "explore: " ?m " shows an unknown code (" ?r "); trying again later")
    (assert (explore-skip (machine ?m) (until (+ (now) 10.0))))
   else
    (log-info "explore: " ?m " is a " ?type)
    (assert (explored-by-me (machine ?m) (type ?type)))
    (assert (explore-report-now)))
  (retract ?p)
  (assert (explore-pos (machine (ring-after ?m))))
  (task-finished ?t (neq ?type NONE))
)

(defrule explore-failed
  (declare (salience ?*PRIORITY-DECIDE*))
  ?t <- (task (kind EXPLORE) (state FAILED) (place ?m))
  ?p <- (explore-pos)
  =>
  (assert (explore-skip (machine ?m) (until (+ (now) 20.0))))
  (retract ?p)
  (assert (explore-pos (machine (ring-after ?m))))
  (task-finished ?t FALSE)
)

; Reports: everything we explored that the refbox has not listed yet, now and every 2 s.
(deffunction explore-send-report ()
  (bind ?msg (pb-create "llsf_msgs.MachineReport"))
  (bind ?n 0)
  (do-for-all-facts ((?e explored-by-me) (?m machine))
      (and (eq ?m:name ?e:machine) (eq ?m:explored FALSE))
    (bind ?entry (pb-create "llsf_msgs.MachineReportEntry"))
    (pb-set-field ?entry "name" (str-cat ?m:name))
    (pb-set-field ?entry "type" (str-cat ?e:type))
    (pb-add-list ?msg "machines" ?entry)
    (pb-destroy ?entry)
    (bind ?n (+ ?n 1)))
  (if (> ?n 0) then (pb-broadcast ?msg))
  (pb-destroy ?msg)
)

(defrule explore-report-now
  (declare (salience ?*PRIORITY-DECIDE*))
  ?f <- (explore-report-now)
  =>
  (retract ?f)
  (explore-send-report)
)

(defrule explore-report-periodic
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase EXPLORATION))
  ?t <- (timer (name explore-report) (time $?last) (seq ?s))
  (explored-by-me)
  (time $?now&:(timeout ?now ?last 2.0))
  =>
  (modify ?t (time ?now) (seq (+ ?s 1)))
  (explore-send-report)
)
