(defrule by-eval
  (time $?)
  (not (done))
  =>
  (assert (done))
  (eval "(no-such-fn 1)"))
