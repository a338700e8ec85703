; SPDX-License-Identifier: MIT
; Team agents, common part (used by llsf2013 and auction) -- globals.
; A directory of agent files is loaded in name order (00_ ... 90_); an agent is this directory
; followed by its own (clips/agents/llsf2013, clips/agents/auction). See docs/agents.md.

(defglobal
  ; salience bands (as in the Carologistics agents)
  ?*PRIORITY-WM-MARK* = 1000   ; bookkeeping that only sets a global (40_worldmodel.clp)
  ?*PRIORITY-REFBOX* = 300
  ?*PRIORITY-WM* = 200
  ?*PRIORITY-TASK* = 100
  ?*PRIORITY-DECIDE* = 0
  ?*PRIORITY-LOW* = -100
  ; production phase length (s) for the time-left role change
  ?*PRODUCTION-TIME* = 900
)
