#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Frames of unknown types and with garbage payloads are skipped on a stream (the framing is intact); the valid frames around them arrive."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
s = tcp_connect(hub.stream_port)
s.sendall(lock_frame(1) + header(7, 7, 3) + b"abc" + header(2100, 1, 4) + b"\xff\xff\xff\xff" +
          header(2100, 1, 0) + lock_frame(2))
time.sleep(0.3)
check(not closed_by_peer(s, 0.1), "the connection was closed")
s.close()
_, summary, _ = hub.finish()
print(summary)
