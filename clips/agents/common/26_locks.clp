; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- locks. With locks off (confval
; /clips-agent/use-locks FALSE, the default until the lock protocol is enabled for the agent)
; every request is granted at once.

(defrule locks-off-grant
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (lock-request (resource ?res))
  (test (eq (cfg "/clips-agent/use-locks" FALSE) FALSE))
  =>
  (retract ?r)
  (assert (lock-granted (resource ?res)))
)

(defrule locks-off-release
  (declare (salience ?*PRIORITY-TASK*))
  ?r <- (lock-release (resource ?res))
  (test (eq (cfg "/clips-agent/use-locks" FALSE) FALSE))
  =>
  (retract ?r)
  (do-for-all-facts ((?g lock-granted)) (eq ?g:resource ?res) (retract ?g))
)
