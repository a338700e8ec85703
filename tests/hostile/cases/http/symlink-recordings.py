#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A symbolic link in the recordings folder that leads out of it is refused with 403 (names the path), even when the target is a readable file."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

import json
srv = Serve()
outside = os.path.join(TMP, "outside.jsonl")
with open(outside, "w") as f:
    f.write('{"format": "llsfsim-recording"}\n')
os.makedirs(os.path.join(srv.recordings, "x"))
os.symlink(outside, os.path.join(srv.recordings, "x", "evil.jsonl"))
status, body = http_get(srv.port, "/api/recordings/x/evil.jsonl")
srv.stop()
print(status, json.loads(body)["error"])
