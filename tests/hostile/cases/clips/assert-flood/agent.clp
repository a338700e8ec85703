(defrule flood
  (time $?)
  (not (done))
  =>
  (assert (done))
  (loop-for-count (?i 1 20000000) (assert (x ?i))))
