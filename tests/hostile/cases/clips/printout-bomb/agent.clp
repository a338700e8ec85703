(defrule shout
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?s "xxxxxxxxxxxxxxxx") (loop-for-count 15 (bind ?s (str-cat ?s ?s))) (printout t ?s ?s ?s crlf))
