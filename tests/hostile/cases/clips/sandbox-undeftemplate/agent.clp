(defrule pull
  (time $?)
  (not (done))
  =>
  (assert (done))
  (undeftemplate pose))
