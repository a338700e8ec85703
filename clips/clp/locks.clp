; SPDX-License-Identifier: MIT
; Built-in: resource locks (clips/src/locks_feature.cpp, docs/locks.md), Fawkes-style facts.
; Off unless AgentConfig::locks is set. The agent asserts
;   (lock (type GET) (agent ?*ROBOT-NAME*) (resource M1))      ; ask for M1
;   (lock (type RELEASE) (agent ?*ROBOT-NAME*) (resource M1))  ; give it back (sent 0.5 m away)
; and the feature answers with (lock (type ACCEPT|REFUSE) ...) (the GET fact goes),
; (lock (type RELEASE_RVCD) ...) (the RELEASE fact goes; the RVCD fact is retracted at salience
; -9000, match it in the cycle it appears) and keeps one (lock-role MASTER|SLAVE) fact.
;
; GET and RELEASE of one resource exclude each other: handing one of them to the lock manager
; retracts the other, so the fact that stays is the request the manager works on. A GET while
; the robot's own RELEASE is pending takes the lock back (or asks anew if the RELEASE went out);
; that RELEASE will never be answered, and if its fact stayed, the agent's next RELEASE -- an
; identical fact, which CLIPS does not assert twice -- would never reach the manager: the
; resource would stay locked for the rest of the game (the lock trap, docs/locks.md).

(deftemplate lock
  (slot type (type SYMBOL) (allowed-values GET REFUSE ACCEPT RELEASE RELEASE_RVCD))
  (slot agent (type SYMBOL))
  (slot resource (type SYMBOL))
)

; The agent's own requests go to the lock manager (lock-request / lock-release are C++). Each
; consumes the opposite request of the same resource, handed over or not (its activation goes).
(defrule lock-own-get
  (declare (salience 10000))
  (lock (type GET) (agent ?a&:(eq ?a ?*ROBOT-NAME*)) (resource ?r))
  =>
  (do-for-all-facts ((?l lock)) (and (eq ?l:type RELEASE) (eq ?l:agent ?a) (eq ?l:resource ?r))
    (retract ?l))
  (lock-request ?r)
)

(defrule lock-own-release
  (declare (salience 10000))
  (lock (type RELEASE) (agent ?a&:(eq ?a ?*ROBOT-NAME*)) (resource ?r))
  =>
  (do-for-all-facts ((?l lock)) (and (eq ?l:type GET) (eq ?l:agent ?a) (eq ?l:resource ?r))
    (retract ?l))
  (lock-release ?r)
)

; A GET is answered by ACCEPT or REFUSE; a RELEASE by RELEASE_RVCD.
(defrule lock-get-answered
  (declare (salience 9000))
  ?g <- (lock (type GET) (agent ?a) (resource ?r))
  (lock (type ACCEPT|REFUSE) (agent ?a) (resource ?r))
  =>
  (retract ?g)
)

(defrule lock-release-answered
  (declare (salience 9000))
  ?l <- (lock (type RELEASE) (agent ?a) (resource ?r))
  (lock (type RELEASE_RVCD) (agent ?a) (resource ?r))
  =>
  (retract ?l)
)

(defrule lock-retract-rvcd
  (declare (salience -9000))
  ?l <- (lock (type RELEASE_RVCD))
  =>
  (retract ?l)
)

; One (lock-role MASTER|SLAVE) fact; the feature replaces it when the role changes.
(defrule lock-role-unique
  (declare (salience 10000))
  ?old <- (lock-role ?)
  ?new <- (lock-role ?)
  (test (< (fact-index ?old) (fact-index ?new)))
  =>
  (retract ?old)
)
