(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?m (create$ a b)) (loop-for-count 40 (bind ?m (replace$ ?m 1 1 ?m))))
