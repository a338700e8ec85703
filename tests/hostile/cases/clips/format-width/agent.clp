(defrule pad
  (time $?)
  (not (done))
  =>
  (assert (done))
  (format nil "%2000000000d" 1))
