(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?m (create$ a)) (loop-for-count 40 (bind ?m (insert$ ?m 1 ?m))))
