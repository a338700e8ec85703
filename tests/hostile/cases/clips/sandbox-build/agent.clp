(defrule by-build
  (time $?)
  (not (done))
  =>
  (assert (done))
  (build "(defrule x => (remove \"/tmp/llsf-x\"))"))
