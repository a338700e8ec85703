(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?m (create$ a)) (loop-for-count 40 (bind ?m (create$ ?m ?m))))
