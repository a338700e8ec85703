(defrule split
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?s "a ") (loop-for-count 30 (bind ?s (str-cat ?s ?s))) (explode$ ?s))
