#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A stream frame header announcing 4 GiB closes the connection before anything is allocated for it; the server goes on."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

hub = Hub()
s = tcp_connect(hub.stream_port)
s.sendall(header(2100, 1, 0xFFFFFFFF) + b"\x00" * 1000)
check(closed_by_peer(s, 2.0), "the connection stayed open")
stream_roundtrip_ok(hub)
rss = hub.status("VmHWM")
_, summary, err = hub.finish()
check("3 messages received" in summary, summary)
check("closed (oversized)" in err, f"no log line: {err}")
check(rss < 100_000, f"peak RSS {rss} kB")
print(f"closed at once, peak RSS {rss} kB")
