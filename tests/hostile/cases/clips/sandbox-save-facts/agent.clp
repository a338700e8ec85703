(defrule leak
  (time $?)
  (not (done))
  =>
  (assert (done))
  (save-facts "/tmp/llsf-leak.txt"))
