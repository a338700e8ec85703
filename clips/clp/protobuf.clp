; SPDX-License-Identifier: MIT
; Built-in: received protobuf messages (clips/src/protobuf_feature.cpp). A message received
; since the last cycle becomes a protobuf-msg fact; at the end of the cycle the host retracts the
; facts still there and frees the messages (copy what you need with pb-field-value).

(deftemplate protobuf-msg
  (slot type (type STRING))                      ; full name, e.g. "llsf_msgs.GameState"
  (slot comp-id (type INTEGER))
  (slot msg-type (type INTEGER))
  (slot rcvd-via (type SYMBOL) (allowed-values STREAM BROADCAST) (default BROADCAST))
  (multislot rcvd-from (cardinality 2 2))         ; peer name (string) and peer id (integer)
  (multislot rcvd-at (type INTEGER) (cardinality 2 2))  ; sec usec of simulated time
  (slot client-type (type SYMBOL) (allowed-values SERVER CLIENT PEER) (default PEER))
  (slot client-id (type INTEGER) (default 0))     ; = the peer id
  (slot ptr (type EXTERNAL-ADDRESS))
)
