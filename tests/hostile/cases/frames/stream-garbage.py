#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Random bytes on a stream: the server skips or closes, never crashes; another client then talks normally."""
import os
import sys

sys.path.insert(0, os.environ["CASE_DIR"])
from netpeer import *  # noqa: E402,F401,F403

import random
rng = random.Random(7)
hub = Hub(extra=["--stream-partial-timeout-ms", "500"])
for _ in range(30):
    s = tcp_connect(hub.stream_port)
    try:
        s.sendall(bytes(rng.getrandbits(8) for _ in range(rng.randrange(1, 5000))))
    except OSError:
        pass
    s.close()
stream_roundtrip_ok(hub)
check(hub.alive(), "the hub died")
_, summary, _ = hub.finish()
check("3 messages received" in summary, summary)
print("survived: " + summary)
