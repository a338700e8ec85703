#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A connection that sends half a frame and then nothing is closed after the partial-frame timeout (0.5 s here), and logged."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub(extra=["--stream-partial-timeout-ms", "500"])
s = tcp_connect(hub.stream_port)
f = lock_frame(1)
t0 = time.monotonic()
s.sendall(f[: len(f) // 2])
check(closed_by_peer(s, 3.0), "the connection stayed open")
took = time.monotonic() - t0
_, _, err = hub.finish()
check("closed (partial_frame_timeout)" in err, f"no log line: {err}")
check(0.4 < took < 2.5, f"closed after {took:.2f} s")
print(f"closed after {took:.2f} s")
