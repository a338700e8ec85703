; SPDX-License-Identifier: MIT
; Auction agent -- a Murdoch-style task market (thesis §3.3.2), the rival of the role-based
; llsf2013 agent. Loaded as [clips/agents/common, clips/agents/auction]; see docs/agent-auction.md.
;
; THE MARKET
;   Tasks come from the shared world model (machine facts, synced by Worldmodel messages):
;     FEED m X     bring an X (S0, or an S1 made at a T1 on the way) to machine m: the inputs of
;                  the complex target (a T3/T4) and, while it needs an S2, of a T2 feeding it
;     P3 m i       S0 -> T5 m -> deliver (i = 1..p3-parallel: that many P3 jobs at once)
;     RECYCLE m    a consumed puck beside m -> a recycler (the S0 stays in the holder)
;   A task's key is its content ("FEED M3 S1"), so every robot names a task alike. The
;   auctioneer is the lowest-numbered robot heard from in the last alive-timeout seconds (any
;   robot can be it; a silent robot1 is replaced by robot2). It announces the open task of
;   highest priority (AuctionCall), not one already auctioned, claimed by a robot's heartbeat or
;   finished moments ago. Capable robots bid their estimated cost in seconds (travel at
;   travel-speed + handling times + machine time; a busy robot adds busy-penalty and bids only
;   for tasks of higher priority than its own, dropping its task if it wins). After the bid
;   window the lowest bid wins (AuctionAward); the award is resent until the winner acknowledges
;   it (AuctionAck) and the task is auctioned again if the winner stays silent (award-timeout) or
;   declines. Each robot broadcasts a heartbeat (AuctionStatus, 1 s and at once when a task
;   ends): holding, current task (the claim), outcomes of its last tasks. The auctioneer watches
;   these: a failed task, or a winner silent for silence-timeout, is auctioned again.
;   The winner runs the task as steps of the common task engine (25_tasks.clp), each step chosen
;   from the task and what the robot holds; a task ends when the hands are empty again (a
;   product is delivered on the way, an S2 made at a T2 goes on to the complex target).
;
; This file: configuration, geometry, task discovery, costs, the step planner.
; 61_market.clp: the messages, auctioneer and bidder; 62_market_jobs.clp: running the tasks.

(defglobal ?*AU-SEQ* = 0)

; Where S0s are taken and products delivered (field coordinates, m).
(defglobal ?*AU-INS-X* = 0.3 ?*AU-INS-Y* = 2.8 ?*AU-DEL-X* = 5.3 ?*AU-DEL-Y* = 2.8)

(deftemplate au-peer                  ; another robot as heard in its heartbeats
  (slot name (type SYMBOL)) (slot number (type INTEGER)) (slot seen (type FLOAT))
  (slot holding (type SYMBOL) (default NONE))
  (slot job-id (type INTEGER) (default 0)) (slot job-key (type STRING) (default "")))
(deftemplate au-auction               ; an auction this robot runs
  (slot id (type INTEGER)) (slot key (type STRING)) (slot prio (type INTEGER) (default 0))
  (slot state (type SYMBOL) (default BIDDING))   ; BIDDING AWARDED RUNNING
  (slot deadline (type FLOAT) (default 0.0))
  (slot winner (type SYMBOL) (default NONE)) (slot cost (type FLOAT) (default 0.0))
  (slot since (type FLOAT) (default 0.0))      ; awarded at
  (slot sent (type FLOAT) (default 0.0))       ; award last sent at
  (slot sends (type INTEGER) (default 0))
  (slot seen (type FLOAT) (default 0.0)))      ; winner last seen working on it
(deftemplate au-bid (slot auction (type INTEGER)) (slot bidder (type SYMBOL)) (slot cost (type FLOAT)))
(deftemplate au-cooldown (slot key (type STRING)) (slot until (type FLOAT)))
(deftemplate au-job                   ; the task this robot won and works on
  (slot auction (type INTEGER)) (slot key (type STRING))
  (slot kind (type SYMBOL)) (slot machine (type SYMBOL)) (slot input (type SYMBOL))
  (slot prio (type INTEGER) (default 0)) (slot auctioneer (type SYMBOL))
  (slot steps (type INTEGER) (default 0))
  (slot state (type SYMBOL) (default RUNNING))   ; RUNNING FAILED
  (slot since (type FLOAT) (default 0.0)))
(deftemplate au-done (slot auction (type INTEGER)) (slot ok (type SYMBOL)) (slot at (type FLOAT)))
(deftemplate au-report (slot auction (type INTEGER)) (slot robot (type SYMBOL)) (slot ok (type SYMBOL)))
(deftemplate au-award-in (slot auction (type INTEGER)) (slot key (type STRING))
  (slot prio (type INTEGER) (default 0)) (slot auctioneer (type SYMBOL)))
(deftemplate au-ack-in (slot auction (type INTEGER)) (slot bidder (type SYMBOL))
  (slot accepted (type SYMBOL)))
(deftemplate au-start (slot at (type FLOAT)))
(deftemplate au-configured)   ; when this robot first saw PRODUCTION
(deftemplate au-hold (slot puck (type SYMBOL)) (slot until (type FLOAT)))
(deftemplate au-stats (slot auctions (type INTEGER) (default 0)) (slot awards (type INTEGER) (default 0))
  (slot resends (type INTEGER) (default 0)) (slot reauctions (type INTEGER) (default 0))
  (slot won (type INTEGER) (default 0)) (slot done (type INTEGER) (default 0))
  (slot failed (type INTEGER) (default 0)))

(deffacts au-init
  (timer (name au-status) (time 0 0) (seq 0))
  (timer (name au-announce) (time 0 0) (seq 0))
  (au-stats)
)

; --- configuration (/clips-agent/auction/...) --------------------------------------------------
; Read once into globals (au-configure, at the start and after every (reset)): rule conditions
; test some of them every cycle.
(deffunction au-cfg (?name ?default) (cfg (str-cat "/clips-agent/auction/" ?name) ?default))
(defglobal
  ?*AU-BID-WINDOW* = 1.0        ; s
  ?*AU-AWARD-RESEND* = 0.5      ; s between award resends
  ?*AU-AWARD-TIMEOUT* = 3.0     ; s without acknowledgement: auction again
  ?*AU-SILENCE-TIMEOUT* = 8.0   ; s without the winner's heartbeat claiming the task: auction again
  ?*AU-ALIVE-TIMEOUT* = 5.0     ; s: a peer heard from this recently is alive
  ?*AU-RETRY-DELAY* = 2.0       ; s before a task without bids / failed / declined is announced again
  ?*AU-DONE-COOLDOWN* = 4.0     ; s a finished task is not announced again
  ?*AU-START-GRACE* = 2.0       ; s after the production start to hear the peers first
  ?*AU-ANNOUNCE-PERIOD* = 0.5   ; s between looks for a task to announce
  ?*AU-BUSY-PENALTY* = 40.0     ; s; < 0: busy robots never bid
  ?*AU-SPEED* = 0.5             ; m/s for travel estimates
  ?*AU-H-GET* = 15.0 ?*AU-H-FINISH* = 10.0 ?*AU-H-DELIVER* = 15.0   ; s handling per step
  ?*AU-P3-PARALLEL* = 2         ; P3 tasks per T5 at once
  ?*AU-COMPLEX-UNTIL* = 720.0   ; game time (s) after which no complex set is started
  ?*AU-S1-HOLD* = 20.0          ; s an idle robot keeps an S1
  ?*AU-STEP-TIMEOUT* = 150.0    ; s a step (one skill) may run before it is stopped
  ?*AU-RECYCLE* = TRUE
  ?*AU-PRODUCTS* = (create$ P1P2 P3)
  ?*AU-COMPLEX-CACHE* = (create$)   ; product target ... once the T3, T4 and T5 are known
)
(deffunction au-configure ()
  (bind ?*AU-BID-WINDOW* (au-cfg "bid-window" 1.0))
  (bind ?*AU-AWARD-RESEND* (au-cfg "award-resend" 0.5))
  (bind ?*AU-AWARD-TIMEOUT* (au-cfg "award-timeout" 3.0))
  (bind ?*AU-SILENCE-TIMEOUT* (au-cfg "silence-timeout" 8.0))
  (bind ?*AU-ALIVE-TIMEOUT* (au-cfg "alive-timeout" 5.0))
  (bind ?*AU-RETRY-DELAY* (au-cfg "retry-delay" 2.0))
  (bind ?*AU-DONE-COOLDOWN* (au-cfg "done-cooldown" 4.0))
  (bind ?*AU-START-GRACE* (au-cfg "start-grace" 2.0))
  (bind ?*AU-ANNOUNCE-PERIOD* (au-cfg "announce-period" 0.5))
  (bind ?*AU-BUSY-PENALTY* (au-cfg "busy-penalty" 40.0))
  (bind ?*AU-SPEED* (au-cfg "travel-speed" 0.5))
  (bind ?*AU-H-GET* (au-cfg "handling/get" 15.0))
  (bind ?*AU-H-FINISH* (au-cfg "handling/finish" 10.0))
  (bind ?*AU-H-DELIVER* (au-cfg "handling/deliver" 15.0))
  (bind ?*AU-P3-PARALLEL* (au-cfg "p3-parallel" 2))
  (bind ?*AU-COMPLEX-UNTIL* (au-cfg "complex-until" 720.0))
  (bind ?*AU-S1-HOLD* (au-cfg "s1-hold" 20.0))
  (bind ?*AU-STEP-TIMEOUT* (au-cfg "step-timeout" 150.0))
  (bind ?*AU-RECYCLE* (au-cfg "recycle" TRUE))
  (bind ?*AU-PRODUCTS* (create$))
  (foreach ?p (cfg-list "/clips-agent/auction/products" "P1P2" "P3")
    (bind ?*AU-PRODUCTS* (create$ ?*AU-PRODUCTS* (sym-cat ?p))))
  (bind ?*AU-COMPLEX-CACHE* (create$))
)
(defrule au-configure
  (declare (salience 1000))
  (not (au-configured))
  =>
  (au-configure)
  (assert (au-configured))
)
(deffunction au-bid-window () ?*AU-BID-WINDOW*)
(deffunction au-award-resend () ?*AU-AWARD-RESEND*)
(deffunction au-award-timeout () ?*AU-AWARD-TIMEOUT*)
(deffunction au-silence-timeout () ?*AU-SILENCE-TIMEOUT*)
(deffunction au-alive-timeout () ?*AU-ALIVE-TIMEOUT*)
(deffunction au-retry-delay () ?*AU-RETRY-DELAY*)
(deffunction au-done-cooldown () ?*AU-DONE-COOLDOWN*)
(deffunction au-start-grace () ?*AU-START-GRACE*)
(deffunction au-busy-penalty () ?*AU-BUSY-PENALTY*)
(deffunction au-speed () ?*AU-SPEED*)
(deffunction au-p3-parallel () ?*AU-P3-PARALLEL*)
(deffunction au-complex-until () ?*AU-COMPLEX-UNTIL*)
(deffunction au-s1-hold () ?*AU-S1-HOLD*)
(deffunction au-products () ?*AU-PRODUCTS*)

; --- the world model ---------------------------------------------------------------------------
(deffunction au-x () (bind ?p (find-fact ((?f pose)) TRUE))
  (if (= (length$ ?p) 0) then (return 0.5)) (return (fact-slot-value (nth$ 1 ?p) x)))
(deffunction au-y () (bind ?p (find-fact ((?f pose)) TRUE))
  (if (= (length$ ?p) 0) then (return 1.0)) (return (fact-slot-value (nth$ 1 ?p) y)))
(deffunction au-holding ()
  (bind ?h (find-fact ((?f holding)) TRUE))
  (if (= (length$ ?h) 0) then (return NONE)) (return (fact-slot-value (nth$ 1 ?h) puck)))

(deffunction au-inputs (?type)
  (switch ?type
    (case T1 then (create$ S0)) (case T2 then (create$ S0 S1))
    (case T3 then (create$ S0 S1 S2)) (case T4 then (create$ S0 S1 S2))
    (case T5 then (create$ S0)) (case RECYCLE then (create$ CONSUMED))
    (default (create$))))
(deffunction au-output (?type)
  (switch ?type
    (case T1 then S1) (case T2 then S2) (case T3 then P1) (case T4 then P2) (case T5 then P3)
    (case RECYCLE then S0) (default UNKNOWN)))

(deffunction au-mslot (?m ?slot)
  (bind ?f (find-fact ((?x machine)) (eq ?x:name ?m)))
  (if (= (length$ ?f) 0) then (return nil))
  (return (fact-slot-value (nth$ 1 ?f) ?slot)))
(deffunction au-up (?m)
  (any-factp ((?x machine)) (and (eq ?x:name ?m) (<= ?x:down-until (now)))))
(deffunction au-needs (?m)
  (bind ?needs (create$)) (bind ?loaded (au-mslot ?m loaded-with))
  (foreach ?i (au-inputs (au-mslot ?m mtype))
    (if (not (member$ ?i ?loaded)) then (bind ?needs (create$ ?needs ?i))))
  (return ?needs))
(deffunction au-dist (?x ?y ?m) (distance-to ?x ?y (au-mslot ?m x) (au-mslot ?m y)))

; The up machine of ?type nearest to (?x, ?y); NONE if there is none.
(deffunction au-nearest (?type ?x ?y)
  (bind ?best NONE) (bind ?bd 1000.0)
  (do-for-all-facts ((?m machine)) (and (eq ?m:mtype ?type) (<= ?m:down-until (now)))
    (bind ?d (distance-to ?x ?y ?m:x ?m:y))
    (if (< ?d ?bd) then (bind ?bd ?d) (bind ?best ?m:name)))
  (return ?best))
(deffunction au-first-of-type (?type)
  (bind ?f (find-fact ((?m machine)) (eq ?m:mtype ?type)))
  (if (= (length$ ?f) 0) then (return NONE)) (return (fact-slot-value (nth$ 1 ?f) name)))

; The complex target of a product (P1: the T3, P2: the T4, P1P2: the one farther from the T5).
(deffunction au-complex-target-of (?product)
  (bind ?t3 (au-first-of-type T3)) (bind ?t4 (au-first-of-type T4))
  (if (eq ?product P1) then (return ?t3))
  (if (eq ?product P2) then (return ?t4))
  (bind ?t5 (au-first-of-type T5))
  (if (or (eq ?t3 NONE) (eq ?t5 NONE)) then (return ?t4))
  (if (eq ?t4 NONE) then (return ?t3))
  (if (> (au-dist (au-mslot ?t5 x) (au-mslot ?t5 y) ?t3) (au-dist (au-mslot ?t5 x) (au-mslot ?t5 y) ?t4))
   then (return ?t3) else (return ?t4)))
(deffunction au-complex-target (?product)
  (bind ?i (member$ ?product ?*AU-COMPLEX-CACHE*))
  (if ?i then (return (nth$ (+ ?i 1) ?*AU-COMPLEX-CACHE*)))
  (bind ?c (au-complex-target-of ?product))
  (if (and (neq (au-first-of-type T3) NONE) (neq (au-first-of-type T4) NONE)
           (neq (au-first-of-type T5) NONE)) then
    (bind ?*AU-COMPLEX-CACHE* (create$ ?*AU-COMPLEX-CACHE* ?product ?c)))
  (return ?c))
(deffunction au-complex-targets ()
  (bind ?r (create$))
  (foreach ?ps (au-products)
    (if (neq ?ps P3) then
      (bind ?c (au-complex-target ?ps))
      (if (and (neq ?c NONE) (not (member$ ?c ?r))) then (bind ?r (create$ ?r ?c)))))
  (return ?r))

; The T2 that makes the S2 for complex target ?c: one already loaded, else the nearest to ?c.
(deffunction au-t2-for (?c)
  (bind ?best NONE) (bind ?bd 1000.0)
  (do-for-all-facts ((?m machine)) (and (eq ?m:mtype T2) (<= ?m:down-until (now)))
    (bind ?d (distance-to (au-mslot ?c x) (au-mslot ?c y) ?m:x ?m:y))
    (if (> (length$ ?m:loaded-with) 0) then (bind ?d (- ?d 100.0)))
    (if (< ?d ?bd) then (bind ?bd ?d) (bind ?best ?m:name)))
  (return ?best))

; The complex target an S2 in the hand goes to (NONE: none needs one).
(deffunction au-s2-target (?x ?y)
  (bind ?best NONE) (bind ?bd 1000.0)
  (foreach ?c (au-complex-targets)
    (if (and (au-up ?c) (member$ S2 (au-needs ?c)) (< (au-dist ?x ?y ?c) ?bd)) then
      (bind ?bd (au-dist ?x ?y ?c)) (bind ?best ?c)))
  (return ?best))

; Does anybody (this robot or an alive peer) hold ?puck?
(deffunction au-anyone-holds (?puck)
  (if (eq (au-holding) ?puck) then (return TRUE))
  (any-factp ((?p au-peer)) (and (eq ?p:holding ?puck) (> ?p:seen (- (now) (au-alive-timeout))))))

; --- tasks -------------------------------------------------------------------------------------
(deffunction au-key-kind (?key) (nth$ 1 (explode$ ?key)))
(deffunction au-key-machine (?key) (nth$ 2 (explode$ ?key)))
(deffunction au-key-input (?key)
  (bind ?k (explode$ ?key))
  (if (and (eq (nth$ 1 ?k) FEED) (>= (length$ ?k) 3)) then (return (nth$ 3 ?k)))
  (return NONE))
(deffunction au-key-prio (?key)
  (switch (au-key-kind ?key) (case FEED then 3) (case P3 then 2) (case RECYCLE then 1) (default 0)))

; The tasks the world model asks for, highest priority first.
(deffunction au-world-tasks ()
  (bind ?hi (create$)) (bind ?mid (create$)) (bind ?lo (create$))
  (bind ?gt (fact-slot-value (nth$ 1 (find-fact ((?g game)) TRUE)) time))
  (foreach ?ps (au-products)
    (if (eq ?ps P3)
     then
      (do-for-all-facts ((?m machine)) (and (eq ?m:mtype T5) (<= ?m:down-until (now)))
        (loop-for-count (?i 1 (au-p3-parallel))
          (bind ?mid (create$ ?mid (str-cat "P3 " ?m:name " " ?i)))))
     else
      (bind ?c (au-complex-target ?ps))
      (if (and (neq ?c NONE) (au-up ?c) (< ?gt (au-complex-until))) then
        (bind ?needs (au-needs ?c))
        (foreach ?x (create$ S0 S1)
          (if (member$ ?x ?needs) then (bind ?hi (create$ ?hi (str-cat "FEED " ?c " " ?x)))))
        (if (and (member$ S2 ?needs) (not (au-anyone-holds S2))) then
          (bind ?b (au-t2-for ?c))
          (if (neq ?b NONE) then
            (foreach ?x (au-needs ?b)
              (bind ?key (str-cat "FEED " ?b " " ?x))
              (if (not (member$ ?key ?hi)) then (bind ?hi (create$ ?hi ?key)))))))))
  (if (eq ?*AU-RECYCLE* TRUE) then
    (do-for-all-facts ((?m machine)) (> ?m:consumed 0)
      (bind ?lo (create$ ?lo (str-cat "RECYCLE " ?m:name)))))
  (return (create$ ?hi ?mid ?lo)))

; Is ?key taken: auctioned by me, claimed by an alive robot (or me), or finished moments ago?
(deffunction au-key-taken (?key)
  (if (any-factp ((?a au-auction)) (eq ?a:key ?key)) then (return TRUE))
  (if (any-factp ((?j au-job)) (eq ?j:key ?key)) then (return TRUE))
  (if (any-factp ((?c au-cooldown)) (and (eq ?c:key ?key) (> ?c:until (now)))) then (return TRUE))
  (any-factp ((?p au-peer)) (and (eq ?p:job-key ?key) (> ?p:seen (- (now) (au-alive-timeout))))))

; The auctioneer: no alive peer has a lower number.
(deffunction au-i-am-auctioneer ()
  (not (any-factp ((?p au-peer))
         (and (< ?p:number ?*ROBOT-NUMBER*) (> ?p:seen (- (now) (au-alive-timeout)))))))

; --- costs -------------------------------------------------------------------------------------
(deffunction au-leg (?x ?y ?tx ?ty) (/ (distance-to ?x ?y ?tx ?ty) (au-speed)))

; Estimated seconds for this robot, holding ?h at (?x, ?y), to do ?key; -1: not capable.
(deffunction au-task-cost (?key ?h ?x ?y)
  (bind ?kind (au-key-kind ?key)) (bind ?m (au-key-machine ?key)) (bind ?in (au-key-input ?key))
  (bind ?hget ?*AU-H-GET*) (bind ?hfin ?*AU-H-FINISH*) (bind ?hdel ?*AU-H-DELIVER*)
  (if (eq (au-mslot ?m x) nil) then (return -1.0))
  (bind ?ok (or (eq ?h NONE) (and (eq ?h S0) (neq ?kind RECYCLE))
                (and (eq ?h S1) (eq ?kind FEED) (eq ?in S1))))
  (if (not ?ok) then (return -1.0))
  (bind ?t 0.0) (bind ?px ?x) (bind ?py ?y)
  (if (eq ?kind RECYCLE) then
    (bind ?t (+ (au-leg ?px ?py (au-mslot ?m x) (au-mslot ?m y)) ?hget))
    (bind ?r (au-nearest RECYCLE (au-mslot ?m x) (au-mslot ?m y)))
    (if (eq ?r NONE) then (return -1.0))
    (return (+ ?t (/ (au-dist (au-mslot ?m x) (au-mslot ?m y) ?r) (au-speed)) ?hfin)))
  (if (eq ?h NONE) then
    (bind ?t (+ ?t (au-leg ?px ?py ?*AU-INS-X* ?*AU-INS-Y*) ?hget))
    (bind ?px ?*AU-INS-X*) (bind ?py ?*AU-INS-Y*))
  (if (and (eq ?kind FEED) (eq ?in S1) (neq ?h S1)) then
    (bind ?t1 (au-nearest T1 ?px ?py))
    (if (eq ?t1 NONE) then (return -1.0))
    (bind ?t (+ ?t (/ (au-dist ?px ?py ?t1) (au-speed)) ?hfin 6.0))
    (bind ?px (au-mslot ?t1 x)) (bind ?py (au-mslot ?t1 y)))
  (bind ?t (+ ?t (/ (au-dist ?px ?py ?m) (au-speed)) ?hfin))
  (if (eq ?kind P3) then
    (bind ?t (+ ?t 30.0 (au-leg (au-mslot ?m x) (au-mslot ?m y) ?*AU-DEL-X* ?*AU-DEL-Y*) ?hdel)))
  (return ?t))

; --- steps -------------------------------------------------------------------------------------
; The next step of task (?kind ?m ?in) for a robot holding ?h after ?n steps:
; (KIND place lock) for the task engine, (DONE) or (FAIL).
(deffunction au-step (?kind ?m ?in ?h ?n)
  (bind ?x (au-x)) (bind ?y (au-y))
  (switch ?h
    (case P1 then (return (create$ DELIVER NONE DELIVERY)))
    (case P2 then (return (create$ DELIVER NONE DELIVERY)))
    (case P3 then (return (create$ DELIVER NONE DELIVERY)))
    (case UNKNOWN then (return (create$ LEAVE NONE NONE)))
    (case CONSUMED then
      (bind ?r (au-nearest RECYCLE ?x ?y))
      (if (eq ?r NONE) then (return (create$ WAIT NONE NONE)))
      (return (create$ FINISH ?r ?r)))
    (case S2 then
      (bind ?c (au-s2-target ?x ?y))
      (if (eq ?c NONE) then (return (create$ LEAVE NONE NONE)))
      (return (create$ FINISH ?c ?c)))
    (case NONE then
      (if (> ?n 0) then (return (create$ DONE)))
      (if (eq ?kind RECYCLE) then (return (create$ GET_CONSUMED ?m ?m)))
      (if (eq ?kind LOCAL) then (return (create$ DONE)))
      (return (create$ GET_S0 NONE INS))))
  (if (eq ?kind RECYCLE) then
    (if (> ?n 0) then (return (create$ DONE)) else (return (create$ FAIL))))
  (if (eq ?kind LOCAL) then (return (create$ LEAVE NONE NONE)))
  (if (eq ?h S1) then
    (if (and (eq ?kind FEED) (eq ?in S1)) then (return (create$ FINISH ?m ?m)))
    (return (create$ LEAVE NONE NONE)))
  ; S0
  (if (and (eq ?kind FEED) (eq ?in S1)) then
    (bind ?t1 (au-nearest T1 ?x ?y))
    (if (eq ?t1 NONE) then (return (create$ FAIL)))
    (return (create$ FINISH ?t1 ?t1)))
  (return (create$ FINISH ?m ?m)))
