(defrule wipe
  (time $?)
  (not (done))
  =>
  (assert (done))
  (reset))
