(defrule read-secret
  (time $?)
  =>
  (open "/etc/passwd" secret "r"))
