(defrule wait
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?x (read)))
