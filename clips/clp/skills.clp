; SPDX-License-Identifier: MIT
; Built-in: skills (clips/src/skills_feature.cpp). (skill-call NAME key val ...) sends the skill
; string and asserts (skill (status IDLE)); the host updates the fact each cycle (RUNNING, FINAL,
; FAILED; `result` is what the skills reported, e.g. "DONE" or "M3 red=ON yellow=OFF green=OFF").
; Finished skill facts are retracted at very low salience, as in Fawkes: match
; (skill (name "drive_to") (status FINAL|FAILED)) in the cycle in which it appears. The name is
; a STRING, as in Fawkes' skills.clp, whether skill-call got a symbol or a string.

(deftemplate skill
  (slot name (type STRING))  ; as in Fawkes: (skill (name "drive_to") ...)
  (slot status (type SYMBOL) (allowed-values IDLE RUNNING FINAL FAILED) (default IDLE))
  (slot skill-string (type STRING))
  (slot error (type STRING) (default ""))
  (slot result (type STRING) (default ""))
)

(defrule skill-retract-done
  (declare (salience -9000))
  ?s <- (skill (status FINAL|FAILED))
  =>
  (retract ?s)
)
