#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""With 64 file descriptors (prlimit --nofile) and 100 connections open, accept fails with EMFILE: the server waits instead of spinning at 100 % CPU, logs it once and serves again when descriptors come free."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

import time
srv = Serve(prefix=["prlimit", "--nofile=64", "--"])
conns = []
for _ in range(100):
    try:
        conns.append(tcp_connect(srv.port))
    except OSError:
        break
time.sleep(0.3)
cpu0 = srv.cpu_seconds()
time.sleep(1.0)
cpu = srv.cpu_seconds() - cpu0
for s in conns:
    s.close()
time.sleep(0.5)
check(http_get(srv.port, "/viewer.js")[0] == 200, "not serving after the descriptors came back")
_, _, err = srv.stop()
logged = err.count("cannot accept a connection")
check(cpu < 0.3, f"{cpu:.2f} s CPU in 1 s: spinning")
check(logged >= 1, f"not logged: {err}")
print(f"cpu {cpu:.2f} s in 1 s, logged {'once' if logged == 1 else str(logged) + ' times'}, serves again")
