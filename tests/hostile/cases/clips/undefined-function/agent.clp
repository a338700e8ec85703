(defrule typo
  (time $?)
  (not (done))
  =>
  (assert (done))
  (pritnout t "x" crlf))
