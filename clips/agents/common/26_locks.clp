; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- resources. The task engine asks for
; a resource with (resource-request (resource ?r)), waits for (resource-granted (resource ?r)) or
; (resource-denied (resource ?r)), and gives it back with (resource-release (resource ?r)).
; With the lock protocol on (AgentBrainConfig::locks, which also sets the confval
; /clips-agent/use-locks TRUE) these become the host's lock facts -- (lock (type GET|RELEASE)
; ...) -- and the answer is read with (lock-state ?r) (docs/locks.md); with it off every
; request is granted at once.

(deftemplate resource-pending (slot resource (type SYMBOL)))

(deffunction use-locks () (eq (cfg "/clips-agent/use-locks" FALSE) TRUE))

(defrule locks-off-grant
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (resource-request (resource ?res))
  (test (not (use-locks)))
  =>
  (retract ?r)
  (assert (resource-granted (resource ?res)))
)

(defrule locks-off-release
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (resource-release (resource ?res))
  (test (not (use-locks)))
  =>
  (retract ?r)
  (do-for-all-facts ((?g resource-granted)) (eq ?g:resource ?res) (retract ?g))
)

(defrule locks-on-request
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (resource-request (resource ?res))
  (test (use-locks))
  =>
  (retract ?r)
  (if (eq (lock-state ?res) RELEASING)
   then
    ; Our own release is still pending (it goes out 0.5 m away): ask again once it is through.
    (assert (resource-denied (resource ?res)))
   else
    (assert (resource-pending (resource ?res)))
    ; (the host asserts (lock (type GET) (agent ...) (resource ?res)): the lock template exists
    ; only with the protocol on, so these rules cannot name it)
    (lock-assert GET ?res))
)

(defrule locks-on-answer
  (declare (salience ?*PRIORITY-TASK*))
  ?p <- (resource-pending (resource ?res))
  (time ? ?)
  =>
  (bind ?st (lock-state ?res))
  (if (eq ?st ACCEPTED) then
    (retract ?p)
    (assert (resource-granted (resource ?res))))
  (if (eq ?st REFUSED) then
    (retract ?p)
    (assert (resource-denied (resource ?res))))
)

(defrule locks-on-release
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (resource-release (resource ?res))
  (test (use-locks))
  =>
  (retract ?r)
  (do-for-all-facts ((?g resource-granted)) (eq ?g:resource ?res) (retract ?g))
  (do-for-all-facts ((?g resource-pending)) (eq ?g:resource ?res) (retract ?g))
  (lock-assert RELEASE ?res)
)

; Waiting for a lock next to a resource this robot is still releasing (a release goes out only
; 0.5 m away) could wait forever for a robot that waits for that resource: after two refusals
; the robot drives to its parking spot, which also completes its pending releases.
(deftemplate stepped-aside (slot resource (type SYMBOL)))

(defrule locks-wait-step-aside
  (declare (salience ?*PRIORITY-TASK*))
  (task (state LOCKING|LOCK_WAIT) (lock ?r) (attempts ?a&:(>= ?a 2)))
  (not (stepped-aside (resource ?r)))
  (test (use-locks))
  =>
  (assert (stepped-aside (resource ?r)))
  (skill-call park)
)

(defrule locks-stepped-aside-done
  (declare (salience ?*PRIORITY-TASK*))
  ?f <- (stepped-aside (resource ?r))
  (not (task (state LOCKING|LOCK_WAIT) (lock ?r)))
  =>
  (retract ?f)
)
