(defrule pull
  (time $?)
  (not (done))
  =>
  (assert (done))
  (undefrule time-retract))
