#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A client that drips a frame one byte every 100 ms is still closed when the partial-frame timeout (1 s) runs out: a trickle does not extend it."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub(extra=["--stream-partial-timeout-ms", "1000"])
s = tcp_connect(hub.stream_port)
big = header(2100, 1, 100) + b"\x00" * 100
t0 = time.monotonic()
closed = False
for b in big:
    try:
        s.sendall(bytes([b]))
    except OSError:
        closed = True
        break
    if closed_by_peer(s, 0.1):
        closed = True
        break
took = time.monotonic() - t0
hub.finish()
check(closed, "the connection stayed open")
check(took < 3.0, f"closed after {took:.2f} s")
print(f"closed after {took:.2f} s")
