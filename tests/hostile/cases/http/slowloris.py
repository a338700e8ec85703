#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""50 connections that drip a request header byte by byte: with --request-timeout 1 they are all closed within 3 s, and other clients are served meanwhile."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

import time
srv = Serve(extra=["--request-timeout", "1"])
conns = [tcp_connect(srv.port) for _ in range(50)]
t0 = time.monotonic()
closed = set()
while time.monotonic() - t0 < 3.0 and len(closed) < 50:
    for i, s in enumerate(conns):
        if i in closed:
            continue
        try:
            s.send(b"X")
        except OSError:
            closed.add(i)
            continue
        if closed_by_peer(s, 0.001):
            closed.add(i)
    time.sleep(0.1)
    if time.monotonic() - t0 < 0.5:
        check(http_get(srv.port, "/viewer.js")[0] == 200, "not serving during the attack")
srv.stop()
print(f"closed {len(closed)} of 50 in {time.monotonic() - t0:.1f} s")
