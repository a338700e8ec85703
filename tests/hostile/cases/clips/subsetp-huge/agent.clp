; subsetp of two 900,000-field multifields: 8 x 10^11 comparisons inside one call.
(defrule compare-huge
  (time $?)
  (not (done))
  =>
  (assert (done))
  (bind ?a (create$ 1 2 3 4 5 6 7 8 9))
  (loop-for-count 5 (bind ?a (create$ ?a ?a ?a ?a ?a ?a ?a ?a ?a ?a)))
  (bind ?b (create$ ?a x))
  (printout t (subsetp ?a ?b) crlf))
