(defrule forever
  (time $?)
  (not (done))
  =>
  (assert (done))
  (while TRUE (bind ?x 1)))
