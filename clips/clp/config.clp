; SPDX-License-Identifier: MIT
; Built-in: configuration values (clips/src/config_feature.cpp), asserted after every (reset).

(deftemplate confval
  (slot path (type STRING))
  (slot type (type SYMBOL) (allowed-values FLOAT UINT INT BOOL STRING))
  (slot value)
  (slot is-list (type SYMBOL) (allowed-values TRUE FALSE) (default FALSE))
  (multislot list-value)
)
