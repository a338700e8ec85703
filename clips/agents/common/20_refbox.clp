; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- what the refbox tells the robots (GameState, ExplorationInfo,
; MachineReportInfo, MachineInfo, OrderInfo). Messages are consumed in the cycle they arrive.

(defrule refbox-game-state
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.GameState") (ptr ?p))
  ?g <- (game)
  =>
  (retract ?pf)
  (bind ?t (pb-field-value ?p "game_time"))
  (bind ?secs (+ (pb-field-value ?t "sec") (/ (pb-field-value ?t "nsec") 1000000000.0)))
  (modify ?g (phase (pb-field-value ?p "phase")) (state (pb-field-value ?p "state"))
             (time ?secs))
)

(defrule refbox-exploration-info
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.ExplorationInfo") (ptr ?p))
  (not (signal))
  =>
  (retract ?pf)
  (foreach ?s (pb-field-list ?p "signals")
    (bind ?red OFF) (bind ?yellow OFF) (bind ?green OFF)
    (foreach ?l (pb-field-list ?s "lights")
      (bind ?st (pb-field-value ?l "state"))   ; ON, OFF, BLINK: explore_machine's names
      (switch (pb-field-value ?l "color")
        (case RED then (bind ?red ?st))
        (case YELLOW then (bind ?yellow ?st))
        (case GREEN then (bind ?green ?st))))
    (assert (signal (type (sym-cat (pb-field-value ?s "type")))
                    (code (str-cat "red=" ?red " yellow=" ?yellow " green=" ?green)))))
)

(defrule refbox-exploration-info-known
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.ExplorationInfo"))
  (signal)
  =>
  (retract ?pf)
)

(defrule refbox-machine-report-info
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.MachineReportInfo") (ptr ?p))
  =>
  (retract ?pf)
  ; (a repeat of the last report changes nothing: explored only ever becomes TRUE)
  (if (not (pb-unchanged ?p machine-report-info)) then
    (foreach ?n (pb-field-list ?p "reported_machines")
      (bind ?m (fact-by-slot machine name (sym-cat ?n)))
      (if (and ?m (eq (fact-slot-value ?m explored) FALSE)) then
        (modify ?m (explored TRUE)))))
)

; The machine types are dealt once, at the start of the game, and never change in it
; (docs/refbox.md); the refbox repeats them in every MachineInfo (every 2 s in production). Once
; every machine has its type, later MachineInfos are consumed without a look (as ExplorationInfo
; is once the signals are known): reading 16 entries that change nothing was the dearest rule.
(deftemplate machine-types-known)

(defrule refbox-machine-info
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.MachineInfo") (ptr ?p))
  (not (machine-types-known))
  =>
  (retract ?pf)
  (foreach ?e (pb-field-list ?p "machines")
    (if (pb-has-field ?e "type") then
      (bind ?type (sym-cat (pb-field-value ?e "type")))
      (bind ?name (sym-cat (pb-field-value ?e "name")))
      (if (member$ ?type (create$ T1 T2 T3 T4 T5)) then
        (bind ?m (fact-by-slot machine name ?name))
        (if (and ?m (neq (fact-slot-value ?m mtype) ?type)) then
          (modify ?m (mtype ?type))))))
  (if (not (any-factp ((?m machine)) (eq ?m:mtype UNKNOWN))) then
    (assert (machine-types-known)))
)

(defrule refbox-machine-info-known
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.MachineInfo"))
  (machine-types-known)
  =>
  (retract ?pf)
)

(defrule refbox-order-info
  (declare (salience ?*PRIORITY-REFBOX*))
  ?pf <- (protobuf-msg (type "llsf_msgs.OrderInfo") (ptr ?p))
  =>
  (retract ?pf)
  ; (only this rule changes order facts: a repeat of the last OrderInfo changes nothing)
  (if (not (pb-unchanged ?p order-info)) then
    (foreach ?o (pb-field-list ?p "orders")
      (bind ?id (pb-field-value ?o "id"))
      (bind ?product (pb-field-value ?o "product"))
      (bind ?req (pb-field-value ?o "quantity_requested"))
      (bind ?del (pb-field-value ?o "quantity_delivered"))
      (bind ?b (pb-field-value ?o "delivery_period_begin"))
      (bind ?e (pb-field-value ?o "delivery_period_end"))
      (bind ?x (fact-by-slot order id ?id))
      (if ?x
       then
        (if (neq (fact-slot-value ?x delivered) ?del) then
          (modify ?x (delivered ?del)))
       else
        (assert (order (id ?id) (product ?product) (requested ?req) (delivered ?del)
                       (begin ?b) (end ?e))))))
)
