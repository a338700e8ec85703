#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A LockMessage header with a payload that is not a LockMessage (garbage, missing required fields) is refused as bad_payload."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
s = udp_socket()
for payload in (b"\xff" * 20, b"", b"\x08\x01"):
    s.sendto(header(2100, 1, len(payload)) + payload, (LOOPBACK, hub.ports["robot1"]))
time.sleep(0.3)
counters, _, _ = hub.finish()
print(f"bad_payload {counters['peers'][0]['malformed']['bad_payload']}")
