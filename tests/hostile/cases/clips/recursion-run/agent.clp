(deffunction dive (?n) (+ 1 (dive (+ ?n 1))))
(defrule down
  (time $?)
  (not (done))
  =>
  (assert (done))
  (dive 0))
