(defrule spin
  ?f <- (spin ?n)
  =>
  (retract ?f)
  (assert (spin (+ ?n 1))))
(deffacts start (spin 0))
