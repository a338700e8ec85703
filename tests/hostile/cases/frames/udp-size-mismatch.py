#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Truncated frames and frames with trailing bytes (the size field disagrees with the datagram) are counted as size_mismatch."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
s = udp_socket()
f = lock_frame(1)
for d in (f[:-1], f + b"\x00", f[:9]):
    s.sendto(d, (LOOPBACK, hub.ports["robot1"]))
time.sleep(0.3)
counters, _, _ = hub.finish()
print(f"size_mismatch {counters['peers'][0]['malformed']['size_mismatch']}")
