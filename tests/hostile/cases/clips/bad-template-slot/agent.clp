(defrule where
  (pose (z ?z))
  =>
  (printout t ?z crlf))
