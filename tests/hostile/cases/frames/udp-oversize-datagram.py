#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A 65,000-byte datagram is refused as oversized (the receive buffer is 64 KiB, the limit 1024 bytes)."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub()
s = udp_socket()
s.sendto(header(2100, 1, 65000 - 8) + b"\xAA" * (65000 - 8), (LOOPBACK, hub.ports["robot1"]))
time.sleep(0.3)
rss = hub.status("VmHWM")
counters, _, _ = hub.finish()
print(f"oversized {counters['peers'][0]['malformed']['oversized']}, peak RSS {rss} kB")
