(defrule broken
  (time $?)
  =>
  (assert (x)
