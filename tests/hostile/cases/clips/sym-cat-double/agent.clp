(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?s x) (loop-for-count 40 (bind ?s (sym-cat ?s ?s))))
