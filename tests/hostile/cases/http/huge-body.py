#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A request announcing a 10 GB body is refused with 400 (body limit 64 KiB) without reading or allocating it."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Serve()
a = raw_exchange(srv.port, b"GET / HTTP/1.1\r\nHost: x\r\nContent-Length: 10000000000\r\n\r\n" +
                 b"z" * 100000)
check(a.startswith(b"HTTP/1.1 400"), f"answer {a[:40]!r}")
rss = srv.status("VmHWM")
srv.stop()
print(f"400, peak RSS {rss} kB")
