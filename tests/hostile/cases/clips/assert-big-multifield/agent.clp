(defrule big
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?m (create$ a b c d e f g h i j)) (loop-for-count 7 (bind ?m (create$ ?m ?m ?m ?m ?m ?m ?m ?m ?m ?m))) (assert (x ?m)))
