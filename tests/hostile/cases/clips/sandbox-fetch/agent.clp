(defrule peek
  (time $?)
  (not (done))
  =>
  (assert (done))
  (fetch "/etc/passwd"))
