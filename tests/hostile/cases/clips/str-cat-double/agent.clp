(defrule grow
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?s "xxxxxxxxxxxxxxxx") (loop-for-count 40 (bind ?s (str-cat ?s ?s))))
