; SPDX-License-Identifier: MIT
; Auction agent -- the market protocol (see 60_market_world.clp for the overview).
;   auctioneer: announce (AuctionCall) -> collect bids for bid-window s -> award the lowest
;               (AuctionAward, resent every award-resend s until AuctionAck or a heartbeat
;               claims it; re-auction after award-timeout) -> watch the winner's heartbeats
;               (AuctionStatus): done -> forget (done-cooldown), failed or silent for
;               silence-timeout -> auction again
;   bidder:     AuctionCall -> AuctionBid with the estimated cost if capable;
;               AuctionAward to me -> accept (start the task) or decline, AuctionAck either way
;   everyone:   AuctionStatus heartbeat every 1 s and when a task ends
; Messages to oneself (the auctioneer bidding, winning) are facts, not broadcasts.

(deffunction au-me (?name) (eq (sym-cat ?name) ?*ROBOT-NAME*))

; --- heartbeat ---------------------------------------------------------------------------------

; What a heartbeat tells the auctioneer (also applied to this robot's own auctions).
(deffunction au-apply-status (?robot ?job-id $?done)
  ; ?done: id ok id ok ...
  (foreach ?a (find-all-facts ((?a au-auction))
                (and (eq ?a:winner ?robot) (= ?a:id ?job-id) (neq ?a:state BIDDING)))
    (modify ?a (state RUNNING) (seen (now))))
  (bind ?i 1)
  (while (< ?i (length$ ?done))
    (bind ?id (nth$ ?i ?done)) (bind ?ok (nth$ (+ ?i 1) ?done))
    (if (and (any-factp ((?a au-auction)) (and (= ?a:id ?id) (eq ?a:winner ?robot)))
             (not (any-factp ((?r au-report)) (= ?r:auction ?id)))) then
      (assert (au-report (auction ?id) (robot ?robot) (ok ?ok))))
    (bind ?i (+ ?i 2)))
)

(deffunction au-my-done ()
  (bind ?r (create$))
  (do-for-all-facts ((?d au-done)) TRUE (bind ?r (create$ ?r ?d:auction ?d:ok)))
  (return ?r))

(deffunction au-send-status ()
  (bind ?m (pb-create "llsf_agent_msgs.AuctionStatus"))
  (pb-set-field ?m "robot" (str-cat ?*ROBOT-NAME*))
  (pb-set-field ?m "number" ?*ROBOT-NUMBER*)
  (pb-set-field ?m "holding" (str-cat (au-holding)))
  (bind ?job-id 0)
  (do-for-fact ((?j au-job)) TRUE
    (bind ?job-id ?j:auction)
    (pb-set-field ?m "auction_id" ?j:auction)
    (pb-set-field ?m "task" ?j:key))
  (bind ?done (au-my-done))
  (bind ?i 1)
  (while (< ?i (length$ ?done))
    (pb-add-list ?m "done_ids" (nth$ ?i ?done))
    (pb-add-list ?m "done_ok" (nth$ (+ ?i 1) ?done))
    (bind ?i (+ ?i 2)))
  (pb-broadcast ?m)
  (pb-destroy ?m)
  (au-apply-status ?*ROBOT-NAME* ?job-id ?done)
)

; Send the heartbeat in this cycle (a task ended, one was accepted).
(deffunction au-status-now ()
  (do-for-fact ((?t timer)) (eq ?t:name au-status) (modify ?t (time 0 0))))

(defrule au-status-send
  (declare (salience ?*PRIORITY-WM*))
  ?t <- (timer (name au-status) (time $?last) (seq ?seq))
  (time $?now&:(timeout ?now ?last 1.0))
  =>
  (modify ?t (time ?now) (seq (+ ?seq 1)))
  (au-send-status)
)

(defrule au-status-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionStatus") (ptr ?p))
  =>
  (retract ?pf)
  (bind ?name (sym-cat (pb-field-value ?p "robot")))
  (bind ?job-id (if (pb-has-field ?p "auction_id") then (pb-field-value ?p "auction_id") else 0))
  (bind ?key (if (pb-has-field ?p "task") then (pb-field-value ?p "task") else ""))
  (bind ?hs (pb-field-value ?p "holding"))
  (bind ?holding (if (eq ?hs "") then NONE else (sym-cat ?hs)))
  (if (any-factp ((?x au-peer)) (eq ?x:name ?name))
   then
    (do-for-fact ((?x au-peer)) (eq ?x:name ?name)
      (modify ?x (seen (now)) (holding ?holding) (job-id ?job-id) (job-key ?key)))
   else
    (assert (au-peer (name ?name) (number (pb-field-value ?p "number")) (seen (now))
                     (holding ?holding) (job-id ?job-id) (job-key ?key))))
  (bind ?ids (pb-field-list ?p "done_ids")) (bind ?oks (pb-field-list ?p "done_ok"))
  (bind ?done (create$))
  (loop-for-count (?i 1 (min (length$ ?ids) (length$ ?oks)))
    (bind ?done (create$ ?done (nth$ ?i ?ids) (nth$ ?i ?oks))))
  (au-apply-status ?name ?job-id ?done)
)

; --- auctioneer --------------------------------------------------------------------------------

(defrule au-production-start
  (game (phase PRODUCTION))
  (not (au-start))
  =>
  (assert (au-start (at (now))))
)

(deffunction au-send-award (?a)
  (bind ?w (fact-slot-value ?a winner))
  (bind ?id (fact-slot-value ?a id))
  (if (eq ?w ?*ROBOT-NAME*)
   then
    (assert (au-award-in (auction ?id) (key (fact-slot-value ?a key))
                         (prio (fact-slot-value ?a prio)) (auctioneer ?*ROBOT-NAME*)))
   else
    (bind ?m (pb-create "llsf_agent_msgs.AuctionAward"))
    (pb-set-field ?m "auction_id" ?id)
    (pb-set-field ?m "winner" (str-cat ?w))
    (pb-set-field ?m "task" (fact-slot-value ?a key))
    (pb-set-field ?m "auctioneer" (str-cat ?*ROBOT-NAME*))
    (pb-broadcast ?m)
    (pb-destroy ?m))
)

(deffunction au-stat (?slot)
  (do-for-fact ((?s au-stats)) TRUE
    (switch ?slot
      (case auctions then (modify ?s (auctions (+ ?s:auctions 1))))
      (case awards then (modify ?s (awards (+ ?s:awards 1))))
      (case resends then (modify ?s (resends (+ ?s:resends 1))))
      (case reauctions then (modify ?s (reauctions (+ ?s:reauctions 1))))
      (case won then (modify ?s (won (+ ?s:won 1))))
      (case done then (modify ?s (done (+ ?s:done 1))))
      (case failed then (modify ?s (failed (+ ?s:failed 1)))))))

; This robot's bid for ?key (priority ?prio): the cost, or -1 (not capable, or busy).
(deffunction au-my-bid (?key ?prio)
  (bind ?penalty 0.0)
  (bind ?jobs (find-fact ((?j au-job)) TRUE))
  (if (= (length$ ?jobs) 0)
   then
    ; idle, unless a step of its own (delivering a held product, ...) runs
    (if (any-factp ((?t task)) (neq ?t:kind WAIT)) then (return -1.0))
   else
    (bind ?penalty (au-busy-penalty))
    (if (or (< ?penalty 0.0) (>= (fact-slot-value (nth$ 1 ?jobs) prio) ?prio)) then (return -1.0))
    ; dropping it must not lose a puck: only while fetching an S0 or between steps
    (if (any-factp ((?t task)) (and (neq ?t:kind GET_S0) (eq ?t:state RUNNING))) then
      (return -1.0)))
  (bind ?c (au-task-cost ?key (au-holding) (au-x) (au-y)))
  (if (< ?c 0.0) then (return -1.0))
  (return (+ ?c ?penalty))
)

; Could anybody bid for a task of priority ?prio (this robot, or an alive peer that is idle
; with empty hands or an S0/S1, or busy with a task of lower priority)? If not, the auction
; waits: no calls that nobody can answer.
(deffunction au-anyone-available (?key ?prio)
  (bind ?since (- (now) (au-alive-timeout)))
  (if (any-factp ((?p au-peer))
        (and (> ?p:seen ?since) (member$ ?p:holding (create$ NONE S0 S1))
             (or (= ?p:job-id 0)
                 (and (>= (au-busy-penalty) 0.0) (< (au-key-prio ?p:job-key) ?prio)))))
   then (return TRUE))
  (>= (au-my-bid ?key ?prio) 0.0)
)

; The open task to announce: the first (highest priority) one somebody can bid for.
(deffunction au-next-announce ()
  (foreach ?k (au-world-tasks)
    (if (and (not (au-key-taken ?k)) (au-anyone-available ?k (au-key-prio ?k))) then (return ?k)))
  (return ""))

; Looks for a task to announce every announce-period s while no auction of this robot is open.
(defrule au-announce
  (declare (salience ?*PRIORITY-DECIDE*))
  (game (phase PRODUCTION) (state RUNNING))
  (au-start (at ?s))
  (not (au-auction (state BIDDING)))
  ?t <- (timer (name au-announce) (time $?last))
  (time $?now&:(timeout ?now ?last ?*AU-ANNOUNCE-PERIOD*))
  (test (> (now) (+ ?s (au-start-grace))))
  (test (au-i-am-auctioneer))
  =>
  (modify ?t (time ?now))
  (bind ?key (au-next-announce))
  (if (neq ?key "") then
    (bind ?*AU-SEQ* (+ ?*AU-SEQ* 1))
    (bind ?id (+ (* ?*ROBOT-NUMBER* 100000) ?*AU-SEQ*))
    (bind ?prio (au-key-prio ?key))
    (bind ?deadline (+ (now) (au-bid-window)))
    (assert (au-auction (id ?id) (key ?key) (prio ?prio) (deadline ?deadline)))
    (au-stat auctions)
    (log-info "auction " ?id ": " ?key)
    (bind ?m (pb-create "llsf_agent_msgs.AuctionCall"))
    (pb-set-field ?m "auction_id" ?id)
    (pb-set-field ?m "auctioneer" (str-cat ?*ROBOT-NAME*))
    (pb-set-field ?m "task" ?key)
    (pb-set-field ?m "deadline" ?deadline)
    (pb-set-field ?m "priority" ?prio)
    (bind ?mach (au-key-machine ?key))
    (if (neq ?mach NONE) then (pb-add-list ?m "resources" (str-cat ?mach)))
    (pb-broadcast ?m)
    (pb-destroy ?m)
    (bind ?c (au-my-bid ?key ?prio))
    (if (>= ?c 0.0) then (assert (au-bid (auction ?id) (bidder ?*ROBOT-NAME*) (cost ?c)))))
)

(defrule au-bid-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionBid") (ptr ?p))
  =>
  (retract ?pf)
  (bind ?id (pb-field-value ?p "auction_id"))
  (bind ?b (sym-cat (pb-field-value ?p "bidder")))
  (if (and (any-factp ((?a au-auction)) (and (= ?a:id ?id) (eq ?a:state BIDDING)))
           (not (any-factp ((?x au-bid)) (and (= ?x:auction ?id) (eq ?x:bidder ?b))))) then
    (assert (au-bid (auction ?id) (bidder ?b) (cost (pb-field-value ?p "cost")))))
)

; The bid window is over: the lowest bid wins (ties: the lower robot name).
(defrule au-close
  (declare (salience ?*PRIORITY-DECIDE*))
  ?a <- (au-auction (id ?id) (key ?key) (state BIDDING) (deadline ?d))
  (time ? ?)
  (test (> (now) ?d))
  =>
  (bind ?best NONE) (bind ?bc 0.0)
  (bind ?prio (fact-slot-value ?a prio))
  (do-for-all-facts ((?b au-bid)) (= ?b:auction ?id)
    ; a bidder that won another of my auctions meanwhile (of no lower priority) is busy now
    (if (and (not (any-factp ((?o au-auction))
                    (and (neq ?o:state BIDDING) (eq ?o:winner ?b:bidder) (>= ?o:prio ?prio))))
             (or (eq ?best NONE) (< ?b:cost ?bc)
                 (and (= ?b:cost ?bc) (< (str-compare ?b:bidder ?best) 0)))) then
      (bind ?best ?b:bidder) (bind ?bc ?b:cost))
    (retract ?b))
  (if (eq ?best NONE)
   then
    (retract ?a)
    (assert (au-cooldown (key ?key) (until (+ (now) (au-retry-delay)))))
   else
    (log-info "auction " ?id ": " ?key " -> " ?best " (" ?bc " s)")
    (au-stat awards)
    (bind ?a (modify ?a (state AWARDED) (winner ?best) (cost ?bc) (since (now)) (sent (now))
                        (sends 1) (seen (now))))
    (au-send-award ?a))
)

; No acknowledgement yet: send the award again; after award-timeout, auction the task again.
(defrule au-award-resend
  (declare (salience ?*PRIORITY-DECIDE*))
  ?a <- (au-auction (id ?id) (key ?key) (state AWARDED) (since ?since) (sent ?s) (sends ?n))
  (time ? ?)
  (test (> (now) (+ ?s (au-award-resend))))
  =>
  (if (> (now) (+ ?since (au-award-timeout)))
   then
    (log-warn "auction " ?id ": " ?key ": no answer from " (fact-slot-value ?a winner)
              ", auctioning it again")
    (au-stat reauctions)
    (retract ?a)
   else
    (au-stat resends)
    (au-send-award (modify ?a (sent (now)) (sends (+ ?n 1)))))
)

(defrule au-ack-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionAck") (ptr ?p))
  =>
  (retract ?pf)
  (assert (au-ack-in (auction (pb-field-value ?p "auction_id"))
                     (bidder (sym-cat (pb-field-value ?p "bidder")))
                     (accepted (pb-field-value ?p "accepted"))))
)

(defrule au-ack
  (declare (salience ?*PRIORITY-DECIDE*))
  ?k <- (au-ack-in (auction ?id) (bidder ?b) (accepted ?acc))
  ?a <- (au-auction (id ?id) (key ?key) (winner ?b) (state ?st&~BIDDING))
  =>
  (retract ?k)
  (if (eq ?acc TRUE)
   then (if (eq ?st AWARDED) then (modify ?a (state RUNNING) (seen (now))))
   else
    (log-info "auction " ?id ": " ?b " declined " ?key)
    (au-stat reauctions)
    (retract ?a))
)

(defrule au-ack-stale
  (declare (salience ?*PRIORITY-LOW*))
  ?k <- (au-ack-in)
  =>
  (retract ?k)
)

; The winner reports the task's outcome (heartbeat done_ids): forget it; a failed task becomes
; open again (after a short cool-down), a finished one after done-cooldown (time for the
; world model to tell everybody what changed).
(defrule au-report
  (declare (salience ?*PRIORITY-DECIDE*))
  ?r <- (au-report (auction ?id) (robot ?w) (ok ?ok))
  ?a <- (au-auction (id ?id) (key ?key))
  =>
  (retract ?r ?a)
  (if (eq ?ok TRUE)
   then
    (log-info "auction " ?id ": " ?w " finished " ?key)
    (assert (au-cooldown (key ?key) (until (+ (now) (au-done-cooldown)))))
   else
    (log-info "auction " ?id ": " ?w " failed " ?key ", auctioning it again")
    (au-stat reauctions)
    (assert (au-cooldown (key ?key) (until (+ (now) (au-retry-delay))))))
)

(defrule au-report-stale
  (declare (salience ?*PRIORITY-LOW*))
  ?r <- (au-report)
  =>
  (retract ?r)
)

(defrule au-silent-winner
  (declare (salience ?*PRIORITY-DECIDE*))
  ?a <- (au-auction (id ?id) (key ?key) (state RUNNING) (winner ?w) (seen ?s))
  (time ? ?)
  (test (> (now) (+ ?s (au-silence-timeout))))
  =>
  (log-warn "auction " ?id ": " ?w " is silent, auctioning " ?key " again")
  (au-stat reauctions)
  (retract ?a)
)

(defrule au-cooldown-expired
  (declare (salience ?*PRIORITY-LOW*))
  ?c <- (au-cooldown (until ?u))
  (time ? ?)
  (test (> (now) ?u))
  =>
  (retract ?c)
)

; --- bidder ------------------------------------------------------------------------------------

(defrule au-call-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionCall") (ptr ?p))
  (game (phase PRODUCTION))
  =>
  (retract ?pf)
  (bind ?key (pb-field-value ?p "task"))
  (bind ?prio (if (pb-has-field ?p "priority") then (pb-field-value ?p "priority")
                else (au-key-prio ?key)))
  (bind ?c (au-my-bid ?key ?prio))
  (if (>= ?c 0.0) then
    (bind ?b (pb-create "llsf_agent_msgs.AuctionBid"))
    (pb-set-field ?b "auction_id" (pb-field-value ?p "auction_id"))
    (pb-set-field ?b "bidder" (str-cat ?*ROBOT-NAME*))
    (pb-set-field ?b "cost" ?c)
    (pb-broadcast ?b)
    (pb-destroy ?b))
)

(defrule au-award-receive
  (declare (salience ?*PRIORITY-WM*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionAward") (ptr ?p))
  =>
  (retract ?pf)
  (if (au-me (pb-field-value ?p "winner")) then
    (bind ?key (pb-field-value ?p "task"))
    (assert (au-award-in (auction (pb-field-value ?p "auction_id")) (key ?key)
                         (prio (au-key-prio ?key))
                         (auctioneer (sym-cat (pb-field-value ?p "auctioneer"))))))
)

(defrule au-other-msgs
  (declare (salience ?*PRIORITY-LOW*))
  ?pf <- (protobuf-msg (type "llsf_agent_msgs.AuctionCall"))
  =>
  (retract ?pf)
)

(deffunction au-send-ack (?id ?auctioneer ?accepted)
  (if (eq ?auctioneer ?*ROBOT-NAME*)
   then (assert (au-ack-in (auction ?id) (bidder ?*ROBOT-NAME*) (accepted ?accepted)))
   else
    (bind ?m (pb-create "llsf_agent_msgs.AuctionAck"))
    (pb-set-field ?m "auction_id" ?id)
    (pb-set-field ?m "bidder" (str-cat ?*ROBOT-NAME*))
    (pb-set-field ?m "accepted" ?accepted)
    (pb-broadcast ?m)
    (pb-destroy ?m))
)
