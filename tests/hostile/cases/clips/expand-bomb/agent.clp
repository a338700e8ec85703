(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?s "xxxxxxxxxxxxxxxx") (loop-for-count 15 (bind ?s (str-cat ?s ?s))) (bind ?m (create$ ?s)) (loop-for-count 13 (bind ?m (create$ ?m ?m))) (str-cat (expand$ ?m)))
