; SPDX-License-Identifier: MIT
; Built-in, Fawkes-style agents only (AgentConfig::fawkes, docs/fawkes.md): what Fawkes' clips
; plugin of 2013 loaded into every environment before the agent (its utils.clp, time.clp and the
; clips-agent's init.clp rules), re-implemented here from their documented behaviour. The C++
; side (clips/src/fawkes_feature.cpp, agent.cpp) adds path-load, path-resolve, config-load,
; ff-feature-request, motor-enable/-disable, (now) as (sec usec) and a (reset) that keeps the
; feature facts.

(defglobal
  ?*DEBUG* = 2                        ; 0 none .. 3 most (Fawkes' utils.clp)
  ?*PRIORITY-TIME-RETRACT* = -10000   ; Fawkes' time.clp (the host retracts (time) itself)
  ?*CONFIG_PREFIX* = "/clips-agent"   ; Fawkes' clips-agent init.clp
)

; ---- debug levels -------------------------------------------------------------------------
(deffunction debug-set-level (?level) (bind ?*DEBUG* ?level))
(deffunction debug (?level) (<= ?level ?*DEBUG*))

; ---- lists and sets -----------------------------------------------------------------------
; (append$ ?list item...): the list with the items at its end.
(deffunction append$ (?list $?items) (create$ ?list ?items))

; (randomize$ ?list): the list in a random order (draws from the agent's (random) stream).
(deffunction randomize$ (?list)
  (bind ?out (create$))
  (while (> (length$ ?list) 0)
    (bind ?i (random 1 (length$ ?list)))
    (bind ?out (create$ ?out (nth$ ?i ?list)))
    (bind ?list (delete$ ?list ?i ?i)))
  ?out)

; (set-eq ?a ?b): every member of ?a is in ?b and the other way round.
(deffunction set-eq (?a ?b) (and (subsetp ?a ?b) (subsetp ?b ?a)))

; (set-diff ?a ?b): the members of ?a that are not in ?b, in ?a's order.
(deffunction set-diff (?a ?b)
  (bind ?out (create$))
  (progn$ (?x ?a) (if (not (member$ ?x ?b)) then (bind ?out (create$ ?out ?x))))
  ?out)

(deffunction is-even-int (?n) (= (mod ?n 2) 0))
(deffunction is-odd-int (?n) (= (mod ?n 2) 1))

; ---- strings ------------------------------------------------------------------------------
; (str-replace ?s ?search ?replace): ?s with the first occurrence of ?search replaced.
(deffunction str-replace (?s ?search ?replace)
  (bind ?at (str-index ?search ?s))
  (if (not ?at) then (return ?s))
  (str-cat (sub-string 1 (- ?at 1) ?s) ?replace
           (sub-string (+ ?at (str-length ?search)) (str-length ?s) ?s)))

; (string> ?a ?b): ?a sorts after ?b.
(deffunction string> (?a ?b) (> (str-compare ?a ?b) 0))

; ---- skills (the clips-agent's skills.clp) ------------------------------------------------
; A (skill-update (name N) (status S)) fact sets the status of skill N's fact, as Fawkes'
; clips-agent did with the updates it asserted from the skiller's interface. llsfsim's host
; updates the skill fact itself; the template and its rules serve an agent that asserts updates.
(deftemplate skill-update
  (slot name (type STRING))
  (slot status (type SYMBOL) (allowed-values IDLE RUNNING FINAL FAILED)))

(defrule skill-update
  ?su <- (skill-update (name ?n) (status ?new-status))
  ?sf <- (skill (name ?n) (status ?old-status&~?new-status))
  =>
  (retract ?su)
  (modify ?sf (status ?new-status)))

(defrule skill-update-nochange
  ?su <- (skill-update (name ?n) (status ?new-status))
  (skill (name ?n) (status ?new-status))
  =>
  (retract ?su))

; ---- protobuf -----------------------------------------------------------------------------
(deffunction pb-is-broadcast (?rcvd-via) (eq ?rcvd-via BROADCAST))

; ---- the clips-agent's start-up rules (init.clp) ------------------------------------------
; The host asserts (agent-init), runs (config-load "/clips-agent") and the agent's entry file.
(defrule fawkes-debug-level
  (agent-init)
  (confval (path "/clips-agent/debug-level") (type UINT) (value ?v))
  =>
  (debug-set-level ?v))

(defrule fawkes-clips-debug
  (agent-init)
  (confval (path "/clips-agent/clips-debug") (type BOOL) (value TRUE))
  =>
  (watch facts)
  (watch rules))
