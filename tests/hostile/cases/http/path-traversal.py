#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Path traversal, plain and percent-encoded, with backslashes, NUL and absolute paths: 400, nothing outside the viewer folder is served, the server goes on."""
import os
import sys

sys.path.insert(0, os.path.join(os.environ["CASE_DIR"], "..", "frames"))
from netpeer import *  # noqa: E402,F401,F403

srv = Serve()
targets = ["/../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2fetc%2fpasswd",
           "/%2E%2E%5C%2E%2E%5Cetc%5Cpasswd", "/viewer.js%00.html", "//etc/passwd",
           "/api/recordings/../../etc/passwd", "/api/recordings/%2e%2e/x", "/a/./b", "/%zz"]
for t in targets:
    status, body = http_get(srv.port, t)
    check(status == 400, f"{t}: {status}")
    check("root:" not in body, f"{t}: served /etc/passwd")
status, _ = http_get(srv.port, "/viewer.js")
check(status == 200, "the viewer is no longer served")
srv.stop()
print("all 400, still serving")
