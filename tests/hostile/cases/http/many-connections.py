#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""500 idle connections: 64 are kept, the rest closed at once (logged, not 500 times); when they go, the server serves again."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

import time
srv = Serve()
conns = [tcp_connect(srv.port) for _ in range(500)]
time.sleep(0.3)
kept = sum(1 for s in conns if not closed_by_peer(s, 0.002))
rss = srv.status("VmHWM")
for s in conns:
    s.close()
time.sleep(0.3)
check(http_get(srv.port, "/viewer.js")[0] == 200, "not serving after the attack")
_, _, err = srv.stop()
check(rss < 150_000, f"peak RSS {rss} kB")
print(f"kept {kept} of 500, refusal log lines {err.count('max_connections')}, peak RSS {rss} kB")
