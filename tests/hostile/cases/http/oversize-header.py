#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A 1 MB request header (and a 20,000-field one) is refused with 400 at the 16 KiB limit; the server stays small."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Serve()
a = raw_exchange(srv.port, b"GET / HTTP/1.1\r\nHost: x\r\nX-A: " + b"a" * (1 << 20) + b"\r\n\r\n")
b = raw_exchange(srv.port, b"GET / HTTP/1.1\r\nHost: x\r\n" + b"X: y\r\n" * 20000 + b"\r\n")
status = [int(x[9:12]) if x.startswith(b"HTTP/1.1 ") else 0 for x in (a, b)]
check(status == [400, 400], f"answers {status}")
rss = srv.status("VmHWM")
check(http_get(srv.port, "/viewer.js")[0] == 200, "no longer serving")
srv.stop()
check(rss < 150_000, f"peak RSS {rss} kB")
print(f"{status[0]} {status[1]}, peak RSS {rss} kB")
