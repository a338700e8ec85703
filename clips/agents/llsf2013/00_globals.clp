; SPDX-License-Identifier: MIT
; LLSF 2013 team agent (thesis: incremental task-level reasoning with roles) -- globals.
; Files of this directory are loaded in name order (00_ ... 90_). See docs/agent-llsf2013.md.

(defglobal
  ; salience bands (as in the Carologistics agents)
  ?*PRIORITY-REFBOX* = 300
  ?*PRIORITY-WM* = 200
  ?*PRIORITY-TASK* = 100
  ?*PRIORITY-DECIDE* = 0
  ?*PRIORITY-LOW* = -100
  ; production phase length (s) for the time-left role change
  ?*PRODUCTION-TIME* = 900
)
