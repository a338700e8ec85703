(defrule sneak
  (time $?)
  (not (done))
  =>
  (assert (done))
  (load "/etc/passwd"))
