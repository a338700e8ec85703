; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- sharing the world model with the team. Every second each robot
; broadcasts its view of the machines (intermediate inputs lying beside them, consumed pucks,
; down times) in a Worldmodel message; receivers keep, per machine, the newest entry
; (updated_at), so a lost message is repaired by the next one.

(deffacts worldmodel-timer
  (timer (name worldmodel) (time 0 0) (seq 0))
)

(deffunction puck-kind (?p) (return ?p))   ; our symbols are the PuckKind names

; The message is built again only when a machine fact changed since the last broadcast (a new
; machine fact, i.e. an assert or modify, marks it); otherwise the last one goes out again with
; the next seq. Both give the same bytes: a machine's entry lists what its fact holds, in the
; order of the facts.
(defglobal ?*WM-MSG* = FALSE ?*WM-CHANGED* = TRUE)

(defrule wm-machine-changed
  (declare (salience ?*PRIORITY-WM-MARK*))
  (machine)
  =>
  (bind ?*WM-CHANGED* TRUE)
)

(defrule wm-broadcast
  (declare (salience ?*PRIORITY-WM*))
  (game (phase EXPLORATION|PRODUCTION))
  ?t <- (timer (name worldmodel) (time $?last) (seq ?seq))
  (time $?now&:(timeout ?now ?last 1.0))
  =>
  (modify ?t (time ?now) (seq (+ ?seq 1)))
  (if ?*WM-CHANGED* then
    (if ?*WM-MSG* then (pb-destroy ?*WM-MSG*))
    (bind ?*WM-MSG* (pb-create "llsf_agent_msgs.Worldmodel"))
    (pb-set-field ?*WM-MSG* "sender" ?*ROBOT-NAME*)   ; (a symbol or string fills a string field)
    (do-for-all-facts ((?m machine)) (> ?m:updated-at 0.0)
      (bind ?ms (pb-create "llsf_agent_msgs.MachineState"))
      (pb-set-field ?ms "name" ?m:name)
      (foreach ?l ?m:loaded-with (pb-add-list ?ms "loaded_with" ?l))
      (pb-set-field ?ms "junk" ?m:consumed)
      (pb-set-field ?ms "out_of_order_until" ?m:down-until)
      (pb-set-field ?ms "updated_at" ?m:updated-at)
      (pb-add-list ?*WM-MSG* "machines" ?ms)
      (pb-destroy ?ms))
    (bind ?*WM-CHANGED* FALSE))
  (pb-set-field ?*WM-MSG* "seq" (+ ?seq 1))
  (pb-broadcast ?*WM-MSG*)
)

; A robot sends its whole view every second, mostly the same as a second before. An entry is
; taken only when newer than this robot's (and a machine's updated-at only grows), so an entry
; seen before changes nothing: a message equal, but for its seq, to the last one from the same
; robot is skipped without reading its entries (pb-unchanged).
(defrule wm-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.Worldmodel") (ptr ?p) (rcvd-from ?from $?))
  =>
  (retract ?pf)
  (if (not (pb-unchanged ?p ?from "seq")) then
    (foreach ?ms (pb-field-list ?p "machines")
      ; (fact-by-slot: the machine fact by its name, without a do-for-fact over all machines)
      (bind ?m (fact-by-slot machine name (sym-cat (pb-field-value ?ms "name"))))
      (bind ?at (pb-field-value ?ms "updated_at"))
      (if (and ?m (> ?at (fact-slot-value ?m updated-at))) then
        (modify ?m (loaded-with (pb-field-list ?ms "loaded_with"))
                   (consumed (pb-field-value ?ms "junk"))
                   (down-until (pb-field-value ?ms "out_of_order_until"))
                   (updated-at ?at)))))
)

; Messages of the team this agent does not use.
(defrule wm-ignore-other-agent-msgs
  (declare (salience ?*PRIORITY-LOW*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.WorldmodelChange"))
  =>
  (retract ?pf)
)
