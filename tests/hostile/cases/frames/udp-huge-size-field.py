#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A header whose size field says 4 GiB (and other sizes beyond max_frame_bytes) is refused as oversized without allocating."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

hub = Hub()
s = udp_socket()
for size in (0xFFFFFFFF, 0x7FFFFFFF, 1017, 65536):
    s.sendto(header(2100, 1, size) + b"\x00" * 8, (LOOPBACK, hub.ports["robot1"]))
import time
time.sleep(0.3)
check(hub.alive(), "the hub died")
rss = hub.status("VmHWM")
counters, _, _ = hub.finish()
check(rss < 100_000, f"peak RSS {rss} kB")
print(f"oversized {counters['peers'][0]['malformed']['oversized']}, peak RSS {rss} kB")
