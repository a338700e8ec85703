(defrule by-eval
  (time $?)
  (not (done))
  =>
  (assert (done))
  (eval "(open \"/etc/passwd\" f \"r\")"))
