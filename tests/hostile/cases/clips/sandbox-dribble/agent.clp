(defrule trace
  (time $?)
  (not (done))
  =>
  (assert (done))
  (dribble-on "/tmp/llsf-dribble.txt"))
