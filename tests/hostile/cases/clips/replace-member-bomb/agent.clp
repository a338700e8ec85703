(defrule square
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?m (create$ a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a a)) (loop-for-count 4 (bind ?m (replace-member$ ?m ?m a))))
