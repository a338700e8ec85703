#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A later-protocol frame (version 2 header) on the 2013 stream: its bytes read as a 2013 header of an unknown type, skipped; the valid frame after it still arrives."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import struct
import time
hub = Hub()
s = tcp_connect(hub.stream_port)
inner = struct.pack(">HH", 2100, 1) + lock_frame(1)[8:]
s.sendall(struct.pack(">BBBBI", 2, 0, 0, 0, len(inner)) + inner + lock_frame(2))
time.sleep(0.3)
s.close()
_, summary, _ = hub.finish()
print(summary)
