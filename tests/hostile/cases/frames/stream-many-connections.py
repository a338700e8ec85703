#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""300 connections that each start a 1 MiB frame (the attack that took 426 MB): 16 are served, the rest closed at once; the server stays small and serves again once they go."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import time
hub = Hub(extra=["--stream-partial-timeout-ms", "3000"])
conns = []
for _ in range(300):
    try:
        s = tcp_connect(hub.stream_port)
        s.setblocking(False)
        try:
            s.send(header(2100, 1, 1 << 20) + b"\x00" * 65536)
        except OSError:
            pass
        conns.append(s)
    except OSError:
        pass
time.sleep(0.5)
still = [s for s in conns if not closed_by_peer(s, 0.001)]
open_now = len(still)
# The ones kept send their frame up to 100 bytes short of the end: the most they can make the
# server hold.
for s in still:
    s.settimeout(2.0)
    try:
        s.sendall(b"\x00" * ((1 << 20) - 65536 - 100))
    except OSError:
        pass
time.sleep(0.3)
check(hub.alive(), "the hub died")
rss = hub.status("VmHWM")
for s in conns:
    s.close()
time.sleep(0.3)
stream_roundtrip_ok(hub)
_, summary, err = hub.finish()
refused = int(re.search(r"(\d+) connections refused", summary).group(1))
check(open_now <= 16, f"{open_now} connections still open")
check("max_connections" in err, "no log line")
check(err.count("refused a connection") <= 10, "one log line per refusal")
check(rss < 80_000, f"peak RSS {rss} kB")
check("3 messages received" in summary, summary)
print(f"refused {refused}, peak RSS {rss} kB")
