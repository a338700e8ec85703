#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""1,000 WebSocket clients of a live game (the attack that took 296 MB): 32 are accepted, the others get 503; memory stays small and the server keeps serving."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Proc([os.environ["LLSFSIM"], "run", os.path.join(os.environ["CASE_DIR"], "tiny-game.yaml"),
            "--serve", "--port", "0", "--no-db"], r"llsfsim serve: http://")
port = int(re.search(r":(\d+)/", srv.lines[-1]).group(1))
accepted, refused, other, conns = 0, 0, 0, []
for _ in range(1000):
    try:
        s, status = websocket_upgrade(port)
    except OSError:
        other += 1
        continue
    if status == 101:
        accepted += 1
        conns.append(s)  # never reads: the server must not queue the game for it without bound
    elif status == 503:
        refused += 1
        s.close()
    else:
        other += 1
        s.close()
rss = srv.status("VmHWM")
check(http_get(port, "/api/live/status")[0] == 200, "not serving")
_, _, err = srv.stop()
check(rss < 200_000, f"peak RSS {rss} kB")
check(err.count("max_websocket_clients") < 15, "one log line per refusal")
print(f"accepted {accepted}, refused {refused}, other {other}, peak RSS {rss} kB")
