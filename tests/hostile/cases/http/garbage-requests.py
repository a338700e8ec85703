#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Random bytes, binary junk and broken request lines on 200 connections: each gets 400 or is closed; the server goes on."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

import random
rng = random.Random(5)
srv = Serve()
for i in range(200):
    if i % 2:
        data = bytes(rng.getrandbits(8) for _ in range(rng.randrange(1, 3000)))
    else:
        data = rng.choice([b"GET\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n", b"\x00\x01\x02\r\n\r\n",
                           b"GET / HTTP/1.1\r\nContent-Length: -1\r\n\r\n",
                           b"GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n"])
    out = raw_exchange(srv.port, data, timeout=0.5)
    check(out == b"" or out.startswith(b"HTTP/1.1 "), f"odd answer {out[:40]!r}")
check(srv.alive(), "the server died")
check(http_get(srv.port, "/viewer.js")[0] == 200, "not serving")
srv.stop()
print("survived 200 bad requests")
